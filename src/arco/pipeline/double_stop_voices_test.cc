// VoicesOfFrame (refine_stage.h): which of a frame's heard notes become the refinement's
// first and second voice, given where the bow rests.
#include <gtest/gtest.h>

#include <cmath>

#include "arco/pipeline/refine_stage.h"

namespace arco::pipeline {
namespace {

double Hz(double midi) { return 440.0 * std::exp2((midi - 69.0) / 12.0); }

audio::PolyPitchFrame FreePair(double low_midi, double high_midi) {
  audio::PolyPitchFrame p;
  p.count = 2;
  p.notes[0].f0_hz = Hz(low_midi);
  p.notes[1].f0_hz = Hz(high_midi);
  return p;
}

refine::BowRest Rest(int string, int second_string, double off_deg) {
  refine::BowRest r;
  r.string = string;
  r.second_string = second_string;
  r.off_deg = off_deg;
  return r;
}

// A cello's B2 on the G string with a ghost a minor third below in the free analysis (the
// synthetic double-stops take, seed 3): with the bow on the G string alone the tracker's
// B2 stays, with no second voice.
TEST(VoicesOfFrame, ABowOnOneStringKeepsTheSingleNoteTrackersNote) {
  const audio::PolyPitchFrame poly = FreePair(43.8, 47.0);
  const refine::FramePitch heard{Hz(47.0), 0.98};
  const FrameVoices v = VoicesOfFrame(poly, heard, Rest(3, 0, 0.3));
  EXPECT_DOUBLE_EQ(v.first.f0_hz, heard.f0_hz);
  EXPECT_DOUBLE_EQ(v.first.confidence, 0.98);
  EXPECT_EQ(v.upper_f0_hz, 0.0);
  EXPECT_EQ(v.bowed_pair_lower_string, 0);
  // Unvoiced to the tracker (an attack, a rest's noise): still no pair.
  const FrameVoices quiet = VoicesOfFrame(poly, {0.0, 0.0}, Rest(3, 0, 0.3));
  EXPECT_EQ(quiet.first.f0_hz, 0.0);
  EXPECT_EQ(quiet.upper_f0_hz, 0.0);
}

// Where the tracker hears the pair's lower note, or the bow is not clearly on one string
// (between a string and a pair), or nothing is known of the bow, the free pair stands.
TEST(VoicesOfFrame, TheFreePairStandsUnlessTheBowSaysOneString) {
  const audio::PolyPitchFrame poly = FreePair(43.8, 47.0);
  for (const auto& [heard_midi, rest] :
       {std::pair{43.8, Rest(3, 0, 0.3)}, std::pair{47.0, Rest(3, 0, 2.3)},
        std::pair{47.0, refine::BowRest()}}) {
    const FrameVoices v = VoicesOfFrame(poly, {Hz(heard_midi), 0.9}, rest);
    EXPECT_NEAR(v.first.f0_hz, Hz(43.8), 1e-9) << heard_midi << " " << rest.off_deg;
    EXPECT_EQ(v.first.confidence, 1.0);
    EXPECT_NEAR(v.upper_f0_hz, Hz(47.0), 1e-9);
    EXPECT_EQ(v.bowed_pair_lower_string, 0);
  }
}

// The double bass's open E1 with E2 on the A string, the bow on both: the free analysis
// hears E3 (a partial of both) as one note, the pair on strings 4 and 3 is E1 + E2. The pair
// is taken; where the free analysis hears one of the octave's notes the octave is left to
// bow_octaves (a single note's 2nd partial is its octave).
TEST(VoicesOfFrame, ABowOnTwoStringsTakesTheirPairUnlessALoneOctaveIsHeard) {
  audio::PolyPitchFrame poly;
  poly.count = 1;
  poly.notes[0].f0_hz = Hz(52.0);
  poly.on_strings[2][0].f0_hz = Hz(28.0);
  poly.on_strings[2][1].f0_hz = Hz(40.0);
  const FrameVoices v = VoicesOfFrame(poly, {Hz(52.0), 0.9}, Rest(4, 3, 0.4));
  EXPECT_NEAR(v.first.f0_hz, Hz(28.0), 1e-9);
  EXPECT_NEAR(v.upper_f0_hz, Hz(40.0), 1e-9);
  EXPECT_EQ(v.bowed_pair_lower_string, 4);

  poly.notes[0].f0_hz = Hz(28.1);
  const FrameVoices lone = VoicesOfFrame(poly, {Hz(28.1), 0.9}, Rest(4, 3, 0.4));
  EXPECT_NEAR(lone.first.f0_hz, Hz(28.1), 1e-9);
  EXPECT_EQ(lone.upper_f0_hz, 0.0);
  EXPECT_EQ(lone.bowed_pair_lower_string, 0);

  // Not an octave: the pair on the bowed strings whatever the free analysis heard.
  poly.on_strings[2][1].f0_hz = Hz(37.0);
  const FrameVoices sixth = VoicesOfFrame(poly, {Hz(28.1), 0.9}, Rest(4, 3, 0.4));
  EXPECT_NEAR(sixth.upper_f0_hz, Hz(37.0), 1e-9);
  EXPECT_EQ(sixth.bowed_pair_lower_string, 4);
}

FrameVoices Bowed(double low_midi, double high_midi, int lower_string) {
  FrameVoices v;
  v.first = {Hz(low_midi), 1.0};
  v.upper_f0_hz = Hz(high_midi);
  v.bowed_pair_lower_string = lower_string;
  return v;
}

// The viola chord's lower pair D3 + A3 on the C and G strings (chords, seed 3), heard on
// every other frame as F#3 + A3: each ghost frame lies between frames of the pair and takes
// it; the pair's first frame (no frame of it before) and a frame off the bow's pair stay.
TEST(ConsistentBowedPairs, AGhostBetweenFramesOfThePairTakesThePair) {
  std::vector<FrameVoices> v = {Bowed(54.2, 57, 4), Bowed(50, 57, 4), Bowed(54.3, 57, 4),
                                Bowed(50, 57, 4),   Bowed(50, 57, 4), Bowed(54.3, 57, 4),
                                Bowed(50, 57, 4)};
  v.push_back(Bowed(54.3, 57, 0));  // the pair of the free analysis, the bow unknown
  ConsistentBowedPairs(5, &v);
  EXPECT_NEAR(v[0].first.f0_hz, Hz(54.2), 1e-9);  // no frame of D3 + A3 before it
  for (size_t f = 1; f < 7; ++f) EXPECT_NEAR(v[f].first.f0_hz, Hz(50), 1e-9) << f;
  EXPECT_NEAR(v[7].first.f0_hz, Hz(54.3), 1e-9);  // not from the bowed strings
  EXPECT_EQ(v[2].bowed_pair_lower_string, 4);
}

// A change of notes under one bow (sixths up the same two strings) is kept: each pair has
// frames on one side only of the change; the window 0 leaves everything.
TEST(ConsistentBowedPairs, AChangeOfNotesOnTheSameStringsIsKept) {
  std::vector<FrameVoices> v;
  for (int f = 0; f < 6; ++f) v.push_back(Bowed(50, 59, 4));
  for (int f = 0; f < 6; ++f) v.push_back(Bowed(52, 60, 4));
  const std::vector<FrameVoices> before = v;
  ConsistentBowedPairs(5, &v);
  for (size_t f = 0; f < v.size(); ++f) {
    EXPECT_EQ(v[f].first.f0_hz, before[f].first.f0_hz) << f;
    EXPECT_EQ(v[f].upper_f0_hz, before[f].upper_f0_hz) << f;
  }
  std::vector<FrameVoices> ghost = {Bowed(50, 57, 4), Bowed(54, 57, 4), Bowed(50, 57, 4)};
  ConsistentBowedPairs(0, &ghost);
  EXPECT_NEAR(ghost[1].first.f0_hz, Hz(54), 1e-9);
  ConsistentBowedPairs(1, &ghost);
  EXPECT_NEAR(ghost[1].first.f0_hz, Hz(50), 1e-9);
}

}  // namespace
}  // namespace arco::pipeline
