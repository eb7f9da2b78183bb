// The second voice of double stops: string, finger, contact and the second finger's IK on a
// synthetic violin scene (refine/test_scene.h).
#include "arco/refine/double_stop_refine.h"

#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "arco/refine/test_scene.h"
#include "arco/refine/transcription.h"

namespace arco::refine {
namespace {

// The A string (2) stopped by finger 1 two semitones up (B4), 20 frames, with the other
// fingers hovering over their places; the refinement's first voice on it.
struct Fixture {
  testing::Scene scene;
  RefineResult first;
  Fixture() {
    testing::SceneOptions o;
    o.sway = false;
    scene = testing::MakeScene(InstrumentKind::kViolin, {{2, 1, 2.0, 20}}, o);
    RefineOptions options;
    options.num_threads = 1;
    first = Refine(scene.input, options);
  }
  double UpperHz(double semitones_on_e) const {
    return scene.model->open_hz(1) * std::exp2(semitones_on_e / 12.0);
  }
  // A bow's inclination (degrees) resting on `string` alone, or on it and string - 1 (the
  // chord of the bridge's arch through both: the mean of their inclinations).
  double BowDeg(int string) const {
    return scene.model->BowInclinationRad(string) * 180.0 / 3.14159265358979323846;
  }
  double BowOnPairDeg(int string) const { return 0.5 * (BowDeg(string) + BowDeg(string - 1)); }
};

TEST(RefineSecondVoice, SixthFifthAndOpenStringOnTheNextHigherString) {
  const Fixture fx;
  const size_t n = fx.scene.input.pitch.size();
  ASSERT_TRUE(fx.first.contacts[10].pressed());
  ASSERT_EQ(fx.first.contacts[10].string, 2);
  // Frames 5-9: a sixth (E string, 4 semitones: finger 2's place); 10-14: a fifth (E string,
  // 2 semitones: finger 1 across both strings); 15-17: the open E; others none.
  std::vector<double> upper(n, 0.0);
  for (size_t f = 5; f < 10; ++f) upper[f] = fx.UpperHz(4);
  for (size_t f = 10; f < 15; ++f) upper[f] = fx.UpperHz(2);
  for (size_t f = 15; f < 18; ++f) upper[f] = fx.UpperHz(0.1);
  DoubleStopRefineOptions per_frame;
  per_frame.fill_notes = false;
  const DoubleStopRefineResult r = RefineSecondVoice(fx.scene.input, fx.first, upper, per_frame);
  ASSERT_EQ(r.second.size(), n);
  EXPECT_EQ(r.second[2].state, ContactState::kRest);
  for (size_t f = 5; f < 10; ++f) {
    const FrameContact& c = r.second[f];
    ASSERT_TRUE(c.pressed()) << f;
    EXPECT_EQ(c.string, 1);
    EXPECT_EQ(c.finger, 2);
    EXPECT_LT(c.tip_distance_refined_mm, c.tip_distance_vision_mm);
    EXPECT_LT(c.tip_distance_refined_mm, 5.0);  // the regularised IK leaves a few mm
    // The first voice's finger is where the first refinement put it.
    const auto first_tip = [&](const hand::HandPose& p) {
      return hand::FingertipInWorld(fx.scene.input.hand_model, p, hand::Finger::kIndex);
    };
    EXPECT_LT((first_tip(*r.hand[f]) - first_tip(*fx.first.hand[f])).norm(), 1e-9);
  }
  for (size_t f = 10; f < 15; ++f) {
    EXPECT_TRUE(r.second[f].pressed());
    EXPECT_EQ(r.second[f].string, 1);
    EXPECT_EQ(r.second[f].finger, 1);  // one finger stops the fifth
  }
  for (size_t f = 15; f < 18; ++f) {
    EXPECT_EQ(r.second[f].state, ContactState::kOpenString);
    EXPECT_EQ(r.second[f].string, 1);
    EXPECT_EQ(r.second[f].finger, 0);
  }
  EXPECT_EQ(r.summary.frames, 13);
  EXPECT_EQ(r.summary.pressed, 10);
  EXPECT_EQ(r.summary.one_finger_fifths, 5);
  EXPECT_EQ(r.summary.open_string, 3);
  EXPECT_EQ(r.summary.joint_limit_violations, 0);
  // fill_notes: 13 of the note's 20 frames have an upper note, so the others get their
  // median (2 semitones on the E string: the fifth).
  const DoubleStopRefineResult filled = RefineSecondVoice(fx.scene.input, fx.first, upper, {});
  EXPECT_EQ(filled.summary.frames, 20);
  EXPECT_TRUE(filled.second[2].pressed());
  EXPECT_EQ(filled.second[2].string, 1);
  EXPECT_NEAR(filled.second[2].f0_hz, fx.UpperHz(2), 1e-9);
}

TEST(RefineSecondVoice, ThePairOfFingersCorrectsTheFirstVoicesFinger) {
  const Fixture fx;
  const size_t n = fx.scene.input.pitch.size();
  // As if the first voice had been decoded alone onto the ring finger: the hand the
  // cameras saw stops B4 with finger 1, and a sixth above it (E string, 4 semitones) lies
  // under finger 2. Fingers 3 and 4 would also fit one hand frame at these stops, but
  // their tips are far from both contacts.
  RefineResult wrong = fx.first;
  for (FrameContact& c : wrong.contacts) {
    if (c.pressed()) c.finger = 3;
  }
  std::vector<double> upper(n, 0.0);
  for (size_t f = 2; f < 18; ++f) upper[f] = fx.UpperHz(4);
  const DoubleStopRefineResult r = RefineSecondVoice(fx.scene.input, wrong, upper, {});
  ASSERT_EQ(r.first.size(), n);
  int changed = 0;
  for (size_t f = 0; f < n; ++f) {
    if (!r.second[f].pressed()) continue;
    EXPECT_EQ(r.first[f].finger, 1) << f;
    EXPECT_EQ(r.second[f].finger, 2) << f;
    EXPECT_LT(r.first[f].tip_distance_refined_mm, 5.0) << f;
    // The ring finger is back where the cameras saw it.
    for (int d = 0; d < 4; ++d) {
      const int i = hand::DofIndex(hand::Finger::kRing, static_cast<hand::FingerDof>(d));
      EXPECT_EQ(r.hand[f]->angles_rad[static_cast<size_t>(i)],
                fx.scene.input.vision_hand[f]->angles_rad[static_cast<size_t>(i)]);
    }
    ++changed;
  }
  EXPECT_EQ(changed, r.summary.first_fingers_changed);
  EXPECT_GE(changed, 16);
  EXPECT_EQ(r.summary.joint_limit_violations, 0);
  // An upper note on 2 of the note's 20 frames (an octave's partial at a note's edge is
  // more often the note's own) leaves the first voice's finger alone.
  std::vector<double> brief(n, 0.0);
  brief[5] = brief[6] = fx.UpperHz(4);
  const DoubleStopRefineResult kept = RefineSecondVoice(fx.scene.input, wrong, brief, {});
  EXPECT_EQ(kept.summary.first_fingers_changed, 0);
  EXPECT_EQ(kept.first[5].finger, 3);
  EXPECT_NE(kept.second[5].finger, 3);
}

TEST(TranscribeSecondVoice, OneRowPerFirstVoiceNoteWithASecondVoice) {
  const Fixture fx;
  const size_t n = fx.scene.input.pitch.size();
  // A sixth (finger 2 on the E string) over most of the note: one row, in the first
  // voice's note and frames, its pitch the second voice's and its hand position the first's.
  std::vector<double> upper(n, 0.0);
  for (size_t f = 2; f < 18; ++f) upper[f] = fx.UpperHz(4);
  const DoubleStopRefineResult r = RefineSecondVoice(fx.scene.input, fx.first, upper, {});
  ASSERT_FALSE(fx.first.fingering.empty());
  const std::vector<NoteFingering> rows =
      TranscribeSecondVoice(*fx.scene.model, fx.first.fingering, r.second, 440.0);
  ASSERT_EQ(rows.size(), 1u);
  const NoteFingering& row = rows[0];
  const NoteFingering& lower = fx.first.fingering[0];
  EXPECT_EQ(row.note, lower.note);
  EXPECT_EQ(row.first_frame, lower.first_frame);
  EXPECT_EQ(row.last_frame, lower.last_frame);
  EXPECT_EQ(row.state, "pressed");
  EXPECT_EQ(row.string, 1);
  EXPECT_EQ(row.finger, 2);
  EXPECT_EQ(row.midi_note, 76 + 4);  // E5 + 4 semitones: G#5
  EXPECT_NEAR(row.f0_hz, fx.UpperHz(4), 1e-9);
  EXPECT_EQ(row.position_semitones, lower.position_semitones);
  EXPECT_GE(row.pressed_frames, 16);
  // A second voice on a few frames only (a partial at the note's edge): no row.
  std::vector<double> brief(n, 0.0);
  brief[5] = brief[6] = fx.UpperHz(4);
  DoubleStopRefineOptions per_frame;
  per_frame.fill_notes = false;
  const DoubleStopRefineResult few = RefineSecondVoice(fx.scene.input, fx.first, brief, per_frame);
  EXPECT_TRUE(
      TranscribeSecondVoice(*fx.scene.model, fx.first.fingering, few.second, 440.0).empty());
}

// Step 00: the bow says whether two strings sound. The sixth of the first test, heard on
// frames 5-14; the bow rests on the A and E strings together on frames 5-9 (the chord of the
// arch through both: the mean of their inclinations), on the A string alone on 10-14.
// A note bowed on two strings on most of its frames keeps its second voice where the bow's
// inclination reads one string before its last frame on two (a double stop's start
// tracked noisily), but not after it (the release, where the bow leaves the pair).
TEST(RefineSecondVoice, ANoteBowedOnTwoStringsKeepsItsStartButNotItsRelease) {
  const Fixture fx;
  const size_t n = fx.scene.input.pitch.size();  // one note of 20 frames
  const double a_deg = fx.BowDeg(2), both_deg = fx.BowOnPairDeg(2);
  ASSERT_EQ(fx.first.contacts[0].note, fx.first.contacts[n - 1].note);
  const std::vector<double> upper(n, fx.UpperHz(4));
  std::vector<double> bow(n, both_deg);
  for (size_t f = 0; f < 4; ++f) bow[f] = a_deg;      // the start, on the A string alone
  for (size_t f = n - 3; f < n; ++f) bow[f] = a_deg;  // the release
  DoubleStopRefineOptions per_frame;
  per_frame.fill_notes = false;
  const DoubleStopRefineResult r =
      RefineSecondVoice(fx.scene.input, fx.first, upper, per_frame, bow);
  for (size_t f = 0; f < n - 3; ++f) {
    if (!fx.first.contacts[f].pressed()) continue;
    EXPECT_TRUE(r.second[f].pressed()) << f;
  }
  for (size_t f = n - 3; f < n; ++f) EXPECT_EQ(r.second[f].state, ContactState::kRest) << f;
  EXPECT_EQ(r.summary.bow_one_string, 3);
  // A note bowed on two strings on fewer than half its frames is gated frame by frame.
  for (size_t f = 0; f < n; ++f) bow[f] = f % 3 == 0 ? both_deg : a_deg;
  const DoubleStopRefineResult gated =
      RefineSecondVoice(fx.scene.input, fx.first, upper, per_frame, bow);
  for (size_t f = 0; f < n; ++f) {
    if (f % 3 != 0) {
      EXPECT_EQ(gated.second[f].state, ContactState::kRest) << f;
    }
  }
}

TEST(RefineSecondVoice, ABowOnOneStringRulesOutTheSecondVoice) {
  const Fixture fx;
  const InstrumentModel& model = *fx.scene.model;
  const size_t n = fx.scene.input.pitch.size();
  const double a_deg = fx.BowDeg(2), e_deg = fx.BowDeg(1), both_deg = fx.BowOnPairDeg(2);
  // Where the bow rests: the midpoint plays both; each string's own inclination, or a bow a
  // third of the way from the A string's toward the midpoint, plays one.
  const auto rest = [&](double deg) {
    const BowRest r = BowRestOf(model, deg);
    return std::make_pair(r.string, r.second_string);
  };
  EXPECT_EQ(rest(both_deg), std::make_pair(2, 1));
  EXPECT_EQ(rest(both_deg + 0.2 * (e_deg - both_deg)), std::make_pair(2, 1));
  EXPECT_EQ(rest(a_deg), std::make_pair(2, 0));
  EXPECT_EQ(rest(a_deg + 0.33 * (both_deg - a_deg)), std::make_pair(2, 0));
  EXPECT_EQ(rest(e_deg), std::make_pair(1, 0));
  EXPECT_EQ(rest(fx.BowOnPairDeg(3)), std::make_pair(3, 2));  // the D and A strings
  EXPECT_EQ(rest(std::nan("")), std::make_pair(0, 0));        // no bow: the sound decides
  // How far from its rest's own inclination: 0 on it, a third of the way to the pair.
  EXPECT_NEAR(BowRestOf(model, a_deg).off_deg, 0.0, 1e-9);
  EXPECT_NEAR(BowRestOf(model, a_deg + 0.33 * (both_deg - a_deg)).off_deg,
              0.33 * std::abs(both_deg - a_deg),
              1e-9);
  EXPECT_TRUE(std::isnan(BowRestOf(model, std::nan("")).off_deg));
  std::vector<double> upper(n, 0.0);
  for (size_t f = 5; f < 15; ++f) upper[f] = fx.UpperHz(4);
  std::vector<double> bow(n, std::nan(""));
  for (size_t f = 5; f < 10; ++f) bow[f] = both_deg;
  for (size_t f = 10; f < 15; ++f) bow[f] = a_deg;
  bow[12] = std::nan("");  // a lifted or unseen bow leaves the frame to the sound
  DoubleStopRefineOptions per_frame;
  per_frame.fill_notes = false;
  const DoubleStopRefineResult r =
      RefineSecondVoice(fx.scene.input, fx.first, upper, per_frame, bow);
  for (size_t f = 5; f < 10; ++f) EXPECT_TRUE(r.second[f].pressed()) << f;
  for (size_t f : {10, 11, 13, 14}) EXPECT_EQ(r.second[f].state, ContactState::kRest) << f;
  EXPECT_TRUE(r.second[12].pressed());
  EXPECT_EQ(r.summary.bow_one_string, 4);
  EXPECT_EQ(r.summary.frames, 6);
  // The note's other frames are not filled from the frames the bow ruled out.
  DoubleStopRefineOptions filled;
  std::vector<double> heard_where_single(n, 0.0);
  for (size_t f = 0; f < n; ++f) heard_where_single[f] = f % 4 == 0 ? 0.0 : fx.UpperHz(4);
  const std::vector<double> on_a(n, a_deg);
  const DoubleStopRefineResult none =
      RefineSecondVoice(fx.scene.input, fx.first, heard_where_single, filled, on_a);
  for (size_t f = 0; f < n; ++f) EXPECT_FALSE(none.second[f].pressed()) << f;
  // Turned off, the bow is not read.
  DoubleStopRefineOptions off = per_frame;
  off.bow_gate = false;
  const DoubleStopRefineResult heard = RefineSecondVoice(fx.scene.input, fx.first, upper, off, bow);
  for (size_t f = 5; f < 15; ++f) EXPECT_TRUE(heard.second[f].pressed()) << f;
  EXPECT_EQ(heard.summary.bow_one_string, 0);
  // A bow track of another length is a caller's bug.
  EXPECT_THROW(RefineSecondVoice(fx.scene.input, fx.first, upper, per_frame, {1.0}),
               std::invalid_argument);
}

// Step 0a: a double stop's first frames hear its upper note a semitone off (the attack);
// the note's own upper note replaces them within attack_s of its first frame, not later,
// and not in a note whose upper notes disagree (a moving upper voice).
TEST(RefineSecondVoice, ADoubleStopsAttackTakesItsNotesUpperNote) {
  const Fixture fx;
  const size_t n = fx.scene.input.pitch.size();
  size_t start = 0;
  while (start < n && fx.first.contacts[start].note < 0) ++start;
  ASSERT_LT(start + 18, n + 1);
  ASSERT_EQ(fx.scene.input.fps, 30.0);
  std::vector<double> upper(n, 0.0);
  for (size_t f = start; f < n; ++f) upper[f] = fx.UpperHz(4);
  for (size_t f = start; f < start + 3; ++f) upper[f] = fx.UpperHz(3);  // the attack
  upper[start + 12] = fx.UpperHz(3);  // 0.4 s into the note: not its attack
  const DoubleStopRefineResult r = RefineSecondVoice(fx.scene.input, fx.first, upper, {});
  EXPECT_EQ(r.summary.attack_frames, 3);
  for (size_t f = start; f < start + 3; ++f) {
    ASSERT_TRUE(r.second[f].pressed()) << f;
    EXPECT_NEAR(r.second[f].f0_hz, fx.UpperHz(4), 1e-9) << f;
    EXPECT_EQ(r.second[f].finger, 2) << f;
  }
  EXPECT_NEAR(r.second[start + 12].f0_hz, fx.UpperHz(3), 1e-9);
  DoubleStopRefineOptions off;
  off.attack_s = 0;
  const DoubleStopRefineResult kept = RefineSecondVoice(fx.scene.input, fx.first, upper, off);
  EXPECT_EQ(kept.summary.attack_frames, 0);
  EXPECT_NEAR(kept.second[start].f0_hz, fx.UpperHz(3), 1e-9);
  // Half the upper notes a semitone lower: no note's upper note to give.
  for (size_t f = start; f < start + 9; ++f) upper[f] = fx.UpperHz(3);
  const DoubleStopRefineResult moving = RefineSecondVoice(fx.scene.input, fx.first, upper, {});
  EXPECT_EQ(moving.summary.attack_frames, 0);
  EXPECT_NEAR(moving.second[start].f0_hz, fx.UpperHz(3), 1e-9);
  DoubleStopRefineOptions bad;
  bad.attack_s = -0.1;
  EXPECT_FALSE(bad.Validate().ok());
}

// Step 0c: an octave is heard as one note (its partials are the lower note's even ones);
// a bow on both strings through most of the note says two sound. B4 on the A string, the
// bow on the A and E strings on frames 0-14 of its 20, on the A string alone after.
TEST(RefineSecondVoice, ANoteBowedOnTwoStringsGetsItsOctave) {
  const Fixture fx;
  const size_t n = fx.scene.input.pitch.size();
  const double a_deg = fx.BowDeg(2), both_deg = fx.BowOnPairDeg(2);
  const std::vector<double> heard_one(n, 0.0);
  std::vector<double> bow(n, a_deg);
  for (size_t f = 0; f < 15; ++f) bow[f] = both_deg;
  const DoubleStopRefineResult r = RefineSecondVoice(fx.scene.input, fx.first, heard_one, {}, bow);
  int octaves = 0;
  for (size_t f = 0; f < n; ++f) {
    const FrameContact& c1 = fx.first.contacts[f];
    const FrameContact& c2 = r.second[f];
    if (f >= 15 || !c1.pressed()) {
      EXPECT_EQ(c2.state, ContactState::kRest) << f;
      continue;
    }
    ASSERT_TRUE(c2.pressed()) << f;
    EXPECT_EQ(c2.string, 1);
    EXPECT_DOUBLE_EQ(c2.f0_hz, 2 * c1.f0_hz);  // the octave of the frame's own pitch
    ++octaves;
  }
  EXPECT_GE(octaves, 10);
  EXPECT_EQ(r.summary.bow_octaves, octaves);
  // Bowed on two strings on fewer than half its frames (a crossing): one note.
  std::vector<double> crossing(n, a_deg);
  for (size_t f = 0; f < 4; ++f) crossing[f] = both_deg;
  const DoubleStopRefineResult one =
      RefineSecondVoice(fx.scene.input, fx.first, heard_one, {}, crossing);
  for (size_t f = 0; f < n; ++f) EXPECT_EQ(one.second[f].state, ContactState::kRest) << f;
  // Turned off: the sound alone.
  DoubleStopRefineOptions off;
  off.bow_octaves = false;
  const DoubleStopRefineResult none =
      RefineSecondVoice(fx.scene.input, fx.first, heard_one, off, bow);
  EXPECT_EQ(none.summary.bow_octaves, 0);
  for (size_t f = 0; f < n; ++f) EXPECT_EQ(none.second[f].state, ContactState::kRest) << f;
}

// Step 0c in a note heard as two notes: the double bass's A1 + A2 (seed 4), A2 heard on a
// few frames, a ghost a tone below it on a few, one note on the rest. Here B4 + B5 bowed on
// the A and E strings throughout: a ghost A5 on the first 6 frames, B5 on the next 4, one
// note after. The heard median is the ghost; with the bow's unheard octaves it is B5, and
// the ghost frames lie in the note's attack (step 0a).
TEST(RefineSecondVoice, ANoteHeardAsTwoNotesTakesTheOctaveTheBowPlays) {
  const Fixture fx;
  const size_t n = fx.scene.input.pitch.size();
  size_t start = 0;
  while (start < n && fx.first.contacts[start].note < 0) ++start;
  ASSERT_LT(start + 10, n);
  const std::vector<double> bow(n, fx.BowOnPairDeg(2));
  std::vector<double> upper(n, 0.0);
  for (size_t f = start; f < start + 6; ++f) upper[f] = fx.UpperHz(5);
  for (size_t f = start + 6; f < start + 10; ++f) upper[f] = fx.UpperHz(7);
  const DoubleStopRefineResult r = RefineSecondVoice(fx.scene.input, fx.first, upper, {}, bow);
  int octaves = 0;
  for (size_t f = start; f < n; ++f) {
    const FrameContact& c1 = fx.first.contacts[f];
    if (!c1.pressed()) continue;
    const FrameContact& c2 = r.second[f];
    ASSERT_TRUE(c2.pressed()) << f;
    EXPECT_EQ(c2.string, 1) << f;
    EXPECT_NEAR(c2.f0_hz, 2 * c1.f0_hz, 0.005 * c1.f0_hz) << f;
    ++octaves;
  }
  EXPECT_GE(octaves, 15);
  EXPECT_EQ(r.summary.attack_frames, 6);
  EXPECT_EQ(r.summary.bow_octaves, static_cast<int>(n - start) - 10);
  // Without the bow's octaves the note's upper note is the ghost the tracker heard most.
  DoubleStopRefineOptions off;
  off.bow_octaves = false;
  const DoubleStopRefineResult ghost = RefineSecondVoice(fx.scene.input, fx.first, upper, off, bow);
  EXPECT_NEAR(ghost.second[start + 12].f0_hz, fx.UpperHz(5), 1e-9);
}

TEST(RefineSecondVoice, NoHigherStringOrAnUnplayableSpanIsUncertain) {
  const Fixture fx;
  const size_t n = fx.scene.input.pitch.size();
  std::vector<double> upper(n, 0.0);
  upper[6] = fx.UpperHz(12);  // 10 semitones from the first stop: no hand spans it
  upper[7] = fx.scene.model->open_hz(1) * 0.9;  // below the E string's open pitch
  const DoubleStopRefineResult r = RefineSecondVoice(fx.scene.input, fx.first, upper, {});
  EXPECT_EQ(r.second[6].state, ContactState::kUncertain);
  EXPECT_EQ(r.second[7].state, ContactState::kUncertain);
  EXPECT_EQ(r.summary.uncertain, 2);
  // Wrong sizes and invalid options are a caller's bug.
  EXPECT_THROW(RefineSecondVoice(fx.scene.input, fx.first, {1.0}, {}), std::invalid_argument);
  DoubleStopRefineOptions bad;
  bad.max_span_semitones = -1;
  EXPECT_FALSE(bad.Validate().ok());
  bad = {};
  bad.open_tolerance_cents = 500;
  EXPECT_FALSE(bad.Validate().ok());
  bad = {};
  bad.max_iterations = 0;
  EXPECT_FALSE(bad.Validate().ok());
}

}  // namespace
}  // namespace arco::refine

namespace arco::refine {
namespace {

// A rolled 3-note chord D4 + A4 + F#5 on the violin: the lower pair D4 + A4 (9 frames), then
// the upper pair A4 + F#5 held (30 frames), A4 stopped by finger 3 on the D string in both.
// The first voice of the lower pair, decoded alone, took D4 as the open D string (set here on
// Refine's result: the scene's hand stops it on the G string); the chord puts it back on
// the G string below the shared A4, and the pair becomes a fifth under one finger. Not when
// the pairs are further apart than chord_gap_s (two double stops, no chord), nor with
// tie_chords off; and a lower pair already on those strings is left as it is.
TEST(RefineSecondVoice, AChordsLowerPairTakesTheStringsItsUpperPairLeaves) {
  for (const int rest_frames : {0, 12}) {
    testing::SceneOptions o;
    o.sway = false;
    std::vector<testing::SceneNote> notes = {{4, 3, 7.0, 9}};
    if (rest_frames > 0) notes.push_back({0, 0, 0.0, rest_frames});
    notes.push_back({3, 3, 7.0, 30});
    const testing::Scene scene = testing::MakeScene(InstrumentKind::kViolin, notes, o);
    RefineOptions options;
    options.num_threads = 1;
    const RefineResult decoded = Refine(scene.input, options);
    ASSERT_TRUE(decoded.contacts[4].pressed());
    ASSERT_EQ(decoded.contacts[4].string, 4);
    RefineResult first = decoded;
    for (size_t f = 0; f < 9; ++f) {
      FrameContact& c = first.contacts[f];
      if (!c.pressed()) continue;
      c.state = ContactState::kOpenString, c.string = 3, c.finger = 0;
      c.point_in_world_mm = Eigen::Vector3d::Constant(kNaN);
    }
    const size_t upper_start = 9 + static_cast<size_t>(rest_frames);
    ASSERT_TRUE(first.contacts[upper_start + 10].pressed());
    const double a4 = scene.model->open_hz(3) * std::exp2(7.0 / 12.0);
    std::vector<double> upper(scene.input.pitch.size(), 0.0);
    for (size_t f = 0; f < 9; ++f) upper[f] = a4;
    for (size_t f = upper_start; f < upper_start + 30; ++f)
      upper[f] = scene.model->open_hz(2) * std::exp2(9.0 / 12.0);  // F#5
    const DoubleStopRefineResult r = RefineSecondVoice(scene.input, first, upper, {});
    if (rest_frames > 0) {
      EXPECT_EQ(r.summary.chord_frames_moved, 0);
      EXPECT_EQ(r.first[4].string, 3);
      continue;
    }
    int moved = 0;
    for (size_t f = 0; f < 9; ++f) {
      if (first.contacts[f].state != ContactState::kOpenString) continue;
      ++moved;
      EXPECT_TRUE(r.first[f].pressed()) << f;
      EXPECT_EQ(r.first[f].string, 4) << f;
      EXPECT_EQ(r.second[f].string, 3) << f;
      EXPECT_EQ(r.second[f].finger, r.first[f].finger) << f;  // a fifth: one finger
      EXPECT_LT(r.first[f].tip_distance_refined_mm, 10.0) << f;
    }
    EXPECT_GT(moved, 0);
    EXPECT_EQ(r.summary.chord_frames_moved, moved);
    EXPECT_EQ(r.summary.joint_limit_violations, 0);
    DoubleStopRefineOptions off;
    off.tie_chords = false;
    EXPECT_EQ(RefineSecondVoice(scene.input, first, upper, off).first[4].string, 3);
    const DoubleStopRefineResult kept = RefineSecondVoice(scene.input, decoded, upper, {});
    EXPECT_EQ(kept.summary.chord_frames_moved, 0);
    EXPECT_EQ(kept.first[4].string, 4);
  }
}

}  // namespace
}  // namespace arco::refine
