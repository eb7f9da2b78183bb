#include "arco/refine/pitch_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "arco/refine/test_scene.h"

namespace arco::refine {
namespace {

double Hz(double midi) { return 440.0 * std::exp2((midi - 69.0) / 12.0); }

void AddNote(std::vector<FramePitch>* track,
             double midi,
             int frames,
             double vibrato_cents = 0,
             double confidence = 0.9) {
  for (int i = 0; i < frames; ++i) {
    const double cents = vibrato_cents * std::sin(2 * M_PI * 6.0 * i / 30.0);
    track->push_back({Hz(midi + cents / 100.0), confidence});
  }
}
void AddRest(std::vector<FramePitch>* track, int frames) {
  for (int i = 0; i < frames; ++i) track->push_back({0.0, 0.1});
}

TEST(AnalysePitch, RestsLowConfidenceAndNotes) {
  std::vector<FramePitch> track;
  AddRest(&track, 5);
  AddNote(&track, 50, 20);
  AddNote(&track, 52, 20, 0, 0.2);  // a confident tracker would not say 0.2
  track.push_back({NAN, 0.9});
  const PitchAnalysis a = AnalysePitch(track, {});
  ASSERT_EQ(a.notes.size(), 1u);
  EXPECT_EQ(a.notes[0].first_frame, 5);
  EXPECT_EQ(a.notes[0].last_frame, 24);
  EXPECT_NEAR(a.notes[0].f0_hz, Hz(50), 1e-9);
  EXPECT_TRUE(a.notes[0].usable);
  EXPECT_EQ(a.frame_state[0], FrameAudioState::kRest);
  EXPECT_EQ(a.frame_state[10], FrameAudioState::kNote);
  EXPECT_EQ(a.frame_state[30], FrameAudioState::kLowConfidence);
  EXPECT_EQ(a.frame_state[45], FrameAudioState::kRest);
  EXPECT_EQ(a.note_of_frame[10], 0);
  EXPECT_EQ(a.note_of_frame[30], -1);
}

TEST(AnalysePitch, WideVibratoStaysOneNote) {
  std::vector<FramePitch> track;
  AddNote(&track, 57, 90, 45);  // +-45 cents at 6 Hz for 3 s
  const PitchAnalysis a = AnalysePitch(track, {});
  ASSERT_EQ(a.notes.size(), 1u);
  EXPECT_TRUE(a.notes[0].usable);
  EXPECT_EQ(a.notes[0].outlier_frames, 0);
  EXPECT_GT(a.notes[0].modulation_cents, 30);
  EXPECT_NEAR(1200 * std::log2(a.notes[0].f0_hz / Hz(57)), 0.0, 10.0);
}

TEST(AnalysePitch, LegatoSemitoneStepsSplitAtTheStep) {
  std::vector<FramePitch> track;
  AddNote(&track, 57, 30, 25);
  AddNote(&track, 58, 30, 25);
  AddNote(&track, 56, 30, 0);
  const PitchAnalysis a = AnalysePitch(track, {});
  ASSERT_EQ(a.notes.size(), 3u);
  EXPECT_NEAR(static_cast<double>(a.notes[1].first_frame), 30, 1);
  EXPECT_NEAR(static_cast<double>(a.notes[2].first_frame), 60, 1);
  for (const NoteSpan& n : a.notes) EXPECT_TRUE(n.usable);
}

TEST(AnalysePitch, OneNoisyFrameIsAnOutlierAndDoesNotSplitTheNote) {
  std::vector<FramePitch> track;
  AddNote(&track, 45, 40, 20);
  track[20].f0_hz *= 2;  // octave error
  track[31].f0_hz *= 1.5;
  const PitchAnalysis a = AnalysePitch(track, {});
  ASSERT_EQ(a.notes.size(), 1u);
  EXPECT_TRUE(a.notes[0].usable);
  EXPECT_EQ(a.notes[0].outlier_frames, 2);
  EXPECT_EQ(a.frame_state[20], FrameAudioState::kOutlier);
  EXPECT_EQ(a.frame_state[31], FrameAudioState::kOutlier);
  EXPECT_EQ(a.note_of_frame[20], -1);
  EXPECT_EQ(a.frame_state[21], FrameAudioState::kNote);
}

TEST(AnalysePitch, NotesShorterThanTheMinimumAreUncertain) {
  std::vector<FramePitch> track;
  AddNote(&track, 45, 40);
  track[20].f0_hz *= 2;
  track[21].f0_hz *= 2;
  PitchModelOptions o;
  o.min_note_frames = 3;
  const PitchAnalysis a = AnalysePitch(track, o);
  ASSERT_EQ(a.notes.size(), 3u);
  EXPECT_TRUE(a.notes[0].usable);
  EXPECT_FALSE(a.notes[1].usable);
  EXPECT_TRUE(a.notes[2].usable);
  EXPECT_EQ(a.frame_state[20], FrameAudioState::kShortNote);
  EXPECT_EQ(a.frame_state[21], FrameAudioState::kShortNote);
}

TEST(AnalysePitch, PolyphonicAlternationIsNeverAUsableNote) {
  // A double stop seen by a monophonic tracker: the estimate jumps between the two notes
  // (and their octave) with middling confidence.
  std::vector<FramePitch> track;
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> pick(0, 2);
  const double choices[3] = {Hz(57), Hz(61), Hz(69)};
  for (int i = 0; i < 60; ++i) track.push_back({choices[pick(rng)], 0.6});
  const PitchAnalysis a = AnalysePitch(track, {});
  int note_frames = 0;
  for (FrameAudioState s : a.frame_state) note_frames += s == FrameAudioState::kNote ? 1 : 0;
  EXPECT_EQ(note_frames, 0) << "a random double stop must not pass as stable notes";
  EXPECT_EQ(a.frame_state[30], FrameAudioState::kJumping);
}

TEST(AnalysePitch, FastPassageIsNotMistakenForPolyphony) {
  std::vector<FramePitch> track;  // 3-frame notes (a sixteenth at 150 bpm), chromatic
  for (int i = 0; i < 16; ++i) AddNote(&track, 48 + (i % 8), 3);
  const PitchAnalysis a = AnalysePitch(track, {});
  ASSERT_EQ(a.notes.size(), 16u);
  for (const NoteSpan& n : a.notes) EXPECT_TRUE(n.usable);
}

TEST(AnalysePitch, WeakFramesContinueANoteButNeverStartOne) {
  std::vector<FramePitch> track;
  AddNote(&track, 45, 10);
  AddNote(&track, 45, 4, 0, 0.3);  // the tracker loses confidence mid-note
  AddNote(&track, 45, 10);
  AddNote(&track, 52, 6, 0, 0.3);  // a weak new pitch: no note
  AddNote(&track, 45, 3, 0, 0.1);  // below min_confidence_in_note: ends the note
  const PitchAnalysis a = AnalysePitch(track, {});
  ASSERT_EQ(a.notes.size(), 1u);
  EXPECT_EQ(a.notes[0].first_frame, 0);
  EXPECT_EQ(a.notes[0].last_frame, 23);
  EXPECT_EQ(a.frame_state[12], FrameAudioState::kNote);
  EXPECT_EQ(a.frame_state[26], FrameAudioState::kLowConfidence);
  EXPECT_EQ(a.frame_state[31], FrameAudioState::kLowConfidence);
}

TEST(AnalysePitch, ShortClipAndEmptyClip) {
  std::vector<FramePitch> track;
  AddNote(&track, 45, 1);
  const PitchAnalysis a = AnalysePitch(track, {});
  ASSERT_EQ(a.notes.size(), 1u);
  EXPECT_FALSE(a.notes[0].usable);  // 1 frame < min_note_frames
  EXPECT_EQ(a.frame_state[0], FrameAudioState::kShortNote);
  EXPECT_TRUE(AnalysePitch({}, {}).notes.empty());
}

TEST(PitchModelOptions, ValidateRejectsBadValues) {
  EXPECT_TRUE(PitchModelOptions{}.Validate().ok());
  PitchModelOptions o;
  o.min_confidence = 1.5;
  EXPECT_FALSE(o.Validate().ok());
  o = {};
  o.note_change_cents = 0;
  EXPECT_FALSE(o.Validate().ok());
  o = {};
  o.note_change_frames = 0;
  EXPECT_FALSE(o.Validate().ok());
  o = {};
  o.min_note_frames = 0;
  EXPECT_FALSE(o.Validate().ok());
  o = {};
  o.max_outlier_fraction = -0.1;
  EXPECT_FALSE(o.Validate().ok());
  o = {};
  o.vibrato_min_cents = NAN;
  EXPECT_FALSE(o.Validate().ok());
  o = {};
  o.min_confidence_in_note = 0.6;  // above min_confidence
  EXPECT_FALSE(o.Validate().ok());
  o = {};
  o.jump_window_frames = 1;
  EXPECT_FALSE(o.Validate().ok());
  o = {};
  o.max_jumps_in_window = -1;
  EXPECT_FALSE(o.Validate().ok());
  o = {};
  o.contact.open_tolerance_cents = 120;
  EXPECT_FALSE(o.Validate().ok());
  EXPECT_THROW(AnalysePitch({}, o), std::invalid_argument);
}

class Candidates : public ::testing::Test {
 protected:
  InstrumentModel cello = InstrumentModel::Create("cello").value();
  std::vector<StringSegment> strings = testing::StringsInInstrument(cello);
};

TEST_F(Candidates, EveryStringWhoseRangeHoldsThePitch) {
  // D4 (293.66 Hz): A string +5, D string +12, G string +19, C string +26 (out of range).
  const FrameCandidates c = CandidatesForPitch(cello, strings, Hz(62), {});
  ASSERT_EQ(c.stopped.size(), 3u);
  EXPECT_TRUE(c.open_strings.empty());
  EXPECT_EQ(c.stopped[0].string, 1);
  EXPECT_EQ(c.stopped[1].string, 2);
  EXPECT_EQ(c.stopped[2].string, 3);
  // Eq. 2: the octave on the D string sits half way, the contact lies on its string.
  const Candidate& d = c.stopped[1];
  EXPECT_NEAR(d.from_nut_mm, cello.string_length_mm() / 2, 1e-9);
  EXPECT_NEAR(d.semitones_above_open, 12.0, 1e-9);
  const StringSegment& seg = strings[1];
  EXPECT_NEAR((d.point_in_world - seg.PointAtFraction(0.5)).norm(), 0.0, 1e-9);
  // Contact -> pitch round trip through the instrument model.
  const double from_bridge = cello.string_length_mm() - c.stopped[0].from_nut_mm;
  EXPECT_NEAR(PitchAtContact(cello, 1, from_bridge), Hz(62), 1e-9);
}

TEST_F(Candidates, OpenStringIsNoFingerContact) {
  const FrameCandidates c = CandidatesForPitch(cello, strings, 220.0 * std::exp2(10.0 / 1200), {});
  ASSERT_EQ(c.open_strings.size(), 1u);
  EXPECT_EQ(c.open_strings[0], 1);
  for (const Candidate& cand : c.stopped) {
    EXPECT_NE(cand.string, 1) << "the open string must not also be a stopped contact (nut)";
  }
  // A3 is also a fifth up the D string, a ninth up the G and 21 semitones up the C string:
  // the fingered alternatives stay.
  EXPECT_EQ(c.stopped.size(), 3u);
}

TEST_F(Candidates, UnplayableAndUnvoicedPitchesGiveNothing) {
  EXPECT_FALSE(CandidatesForPitch(cello, strings, 40.0, {}).any());    // below C2
  EXPECT_FALSE(CandidatesForPitch(cello, strings, 3000.0, {}).any());  // above every range
  EXPECT_FALSE(CandidatesForPitch(cello, strings, 0.0, {}).any());
  EXPECT_FALSE(CandidatesForPitch(cello, strings, NAN, {}).any());
  // No strings this frame: open strings still known, no stopped point.
  const FrameCandidates c = CandidatesForPitch(cello, {}, Hz(62), {});
  EXPECT_TRUE(c.stopped.empty());
}

}  // namespace
}  // namespace arco::refine
