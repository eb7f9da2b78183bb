// arco mode at note changes and under a lateral fingertip error: the audio's onsets
// (note_boundaries.h), the decoder's emission weights (arco_decode.h) and the
// neighbours' hand shift for a frame the lift test rejected (finger_ik.h).
#include "arco/refine/note_boundaries.h"

#include <gtest/gtest.h>

#include <cmath>

#include "arco/refine/arco_decode.h"
#include "arco/refine/refine.h"
#include "arco/refine/test_scene.h"

namespace arco::refine {
namespace {

using testing::SceneNote;

RefineOptions Arco(int threads = 1) {
  RefineOptions o;
  o.mode = RefineMode::kArco;
  o.num_threads = threads;
  return o;
}

struct Score {
  int pressed = 0;  // truth pressed frames
  int right = 0;    // pressed with the truth's string and finger
};

Score Identification(const testing::Scene& scene, const RefineResult& r) {
  Score s;
  for (size_t f = 0; f < r.contacts.size(); ++f) {
    if (scene.truth_finger[f] == 0) continue;
    ++s.pressed;
    const FrameContact& c = r.contacts[f];
    s.right +=
        c.pressed() && c.string == scene.truth_string[f] && c.finger == scene.truth_finger[f];
  }
  return s;
}

// A fast cello passage (4-frame notes) whose pitch track is at its worst at every note
// change: the new note's first frame still hears the previous note (weakly, so it continues
// that note by hysteresis), the second is a drop-out; one note keeps a single trusted frame.
std::vector<SceneNote> FastPassage() {
  return {{2, 1, 2, 6},
          {2, 3, 4, 4},
          {2, 1, 2, 4},
          {2, 4, 5, 4},
          {1, 1, 2, 4},
          {1, 3, 4, 4},
          {0, 0, 0, 8},
          {3, 1, 2, 4},
          {3, 4, 5, 4},
          {3, 2, 3, 6}};
}

testing::Scene BlurredFastPassage(int* short_note_first) {
  const std::vector<SceneNote> notes = FastPassage();
  testing::Scene scene = testing::MakeScene(InstrumentKind::kCello, notes);
  int first = 0;
  for (size_t i = 0; i < notes.size(); ++i) {
    const bool after_note = i > 0 && notes[i - 1].string > 0;
    if (notes[i].string > 0 && after_note) {
      const size_t f = static_cast<size_t>(first);
      scene.input.pitch[f] = {scene.input.pitch[f - 1].f0_hz, 0.3};  // the previous note, weak
      if (i == 4) scene.input.pitch[f] = {0.0, 0.0};                 // (the short note stays short)
      scene.input.pitch[f + 1] = {0.0, 0.0};                         // a drop-out
      if (i == 3) {  // the third frame weak too: one trusted frame is left (a short note)
        scene.input.pitch[f + 2].confidence = 0.3;
        *short_note_first = first;
      }
    }
    first += notes[i].frames;
  }
  // The fine track's onsets, a quarter of a frame late (its own lag).
  scene.input.audio_notes = testing::AudioNotesOf(*scene.model, notes, 30.0, 1.0 / 120.0);
  return scene;
}

TEST(NoteBoundaries, FramesAtNoteChangesGoToTheNoteSoundingAtTheirTime) {
  int short_first = -1;
  const testing::Scene scene = BlurredFastPassage(&short_first);
  const RefineResult r = Refine(scene.input, Arco());
  const Score with = Identification(scene, r);
  EXPECT_EQ(with.right, with.pressed);
  int boundary = 0;
  for (size_t f = 0; f < r.contacts.size(); ++f) {
    const FrameContact& c = r.contacts[f];
    if (scene.truth_finger[f] == 0) {
      // The rest (frames 26-33) stays a rest: an audio note's window ends at its offset
      // (the onset lead may press the last three frames before the next note).
      if (f >= 26 && f < 31) {
        EXPECT_EQ(c.state, ContactState::kRest) << "frame " << f;
      }
      continue;
    }
    EXPECT_LT((c.point_in_world_mm - scene.truth_contact[f]).norm(), 1e-6) << "frame " << f;
    if (c.reason == ContactReason::kNoteBoundary) {
      ++boundary;
      EXPECT_EQ(r.analysis.frame_state[f], FrameAudioState::kBoundary);
    }
  }
  EXPECT_GE(boundary, 14);  // two per note change (a few may be hand-shifted instead)
  EXPECT_EQ(r.summary.joint_limit_violations, 0);
  // The note with one trusted frame is usable: its audio note covers four frames.
  const int note = r.analysis.note_of_frame[static_cast<size_t>(short_first + 3)];
  ASSERT_GE(note, 0);
  EXPECT_TRUE(r.analysis.notes[static_cast<size_t>(note)].usable);
  EXPECT_EQ(r.analysis.notes[static_cast<size_t>(note)].first_frame, short_first);

  // Without the onsets the short note is not played at all (the onset lead rescues the
  // other changes here, where the fitted hand is already on the new note).
  testing::Scene no_onsets = scene;
  no_onsets.input.audio_notes.clear();
  const RefineResult n = Refine(no_onsets.input, Arco());
  const Score without = Identification(scene, n);
  EXPECT_LE(without.right, with.right - 4);
  // Its frames are not played as the short note: left unpressed, or kept with the
  // neighbouring note's decision and flagged out of reach (keep_unreachable).
  for (int f = short_first; f < short_first + 4; ++f) {
    const FrameContact& c = n.contacts[static_cast<size_t>(f)];
    EXPECT_TRUE(!c.pressed() || c.reason == ContactReason::kOutOfReach) << "frame " << f;
  }
  RefineOptions off = Arco();
  off.decode.audio_onsets = false;
  EXPECT_EQ(Identification(scene, Refine(scene.input, off)).right, without.right);
}

// A glide heard at a note change (ArcoDecodeOptions::glide_frames): the second note's first
// frame sounds, trusted, a pitch between the two notes' (the finger slides on the string).
// The frame stays the second note's (a boundary frame: string and finger decoded with
// it) and its contact is where that pitch is stopped, between the two notes' places; with
// glides off it takes the note's contact, as an untrusted frame still does.
TEST(NoteBoundaries, AHeardGlideIsContactedWhereItSounds) {
  int short_first = -1;
  testing::Scene scene = BlurredFastPassage(&short_first);
  const size_t f = 6;  // the second note's first frame; frame 7 is a drop-out
  scene.input.pitch[f] = {std::sqrt(scene.input.pitch[5].f0_hz * scene.input.pitch[8].f0_hz), 0.9};
  const RefineResult r = Refine(scene.input, Arco());
  const FrameContact& c = r.contacts[f];
  ASSERT_TRUE(c.pressed());
  // This scene's fitted finger is already on the second note's place, farther from the
  // glide's point than the IK may reach: out_of_reach, the decision kept.
  EXPECT_TRUE(c.reason == ContactReason::kNoteBoundary || c.reason == ContactReason::kOutOfReach);
  EXPECT_EQ(r.analysis.frame_state[f], FrameAudioState::kBoundary);
  EXPECT_EQ(c.string, scene.truth_string[f]);
  EXPECT_EQ(c.finger, scene.truth_finger[f]);
  const double before = r.contacts[5].from_nut_mm, after = r.contacts[8].from_nut_mm;
  EXPECT_GT(c.from_nut_mm, std::min(before, after) + 2.0);
  EXPECT_LT(c.from_nut_mm, std::max(before, after) - 2.0);
  // The drop-out after it is not heard: the note's contact.
  EXPECT_LT((r.contacts[7].point_in_world_mm - scene.truth_contact[7]).norm(), 1e-6);
  RefineOptions off = Arco();
  off.decode.glide_frames = 0;
  const RefineResult n = Refine(scene.input, off);
  EXPECT_LT((n.contacts[f].point_in_world_mm - scene.truth_contact[f]).norm(), 1e-6);
  EXPECT_EQ(r.summary.joint_limit_violations, 0);
}

TEST(NoteBoundaries, TrustedFramesOfAnotherNoteAreNeverTaken) {
  int short_first = -1;
  testing::Scene scene = BlurredFastPassage(&short_first);
  // An audio onset two frames early (frames 12-13 are trusted frames of the previous note).
  scene.input.audio_notes[3].onset_s -= 2.0 / 30.0;
  const RefineResult r = Refine(scene.input, Arco());
  for (int f = 12; f < 14; ++f) {
    const FrameContact& c = r.contacts[static_cast<size_t>(f)];
    EXPECT_TRUE(c.pressed()) << "frame " << f;
    EXPECT_EQ(c.finger, scene.truth_finger[static_cast<size_t>(f)]) << "frame " << f;
    EXPECT_EQ(r.analysis.frame_state[static_cast<size_t>(f)], FrameAudioState::kNote);
  }
}

TEST(NoteBoundaries, WindowsFollowTheOnsetsAndTheTolerance) {
  // Direct use: notes at frames 0-9 (pitch A) and 10-19 (pitch B), frames 9-11 untrusted.
  std::vector<FramePitch> pitch(20, FramePitch{220.0, 0.9});
  for (int f = 10; f < 20; ++f) pitch[static_cast<size_t>(f)].f0_hz = 247.0;
  pitch[9] = {220.0, 0.3};   // weak, continues A
  pitch[10] = {0.0, 0.0};    // drop-out
  pitch[11] = {235.0, 0.3};  // between the notes, weak
  PitchModelOptions po;
  const std::vector<AudioNote> audio = {{0.0, 9.5 / 30, 220.0}, {9.5 / 30, 20.0 / 30, 247.0}};
  for (double tol : {0.0, 0.6 / 30}) {
    PitchAnalysis a = AnalysePitch(pitch, po);
    ASSERT_EQ(a.notes.size(), 2u);
    NoteBoundaryOptions bo;
    bo.onset_tolerance_s = tol;
    ApplyAudioNoteBoundaries(audio, 0.0, 30.0, pitch, po, bo, &a);
    // Frame 9 (t = 9/30) is before the onset at 9.5/30 unless the tolerance reaches it.
    EXPECT_EQ(a.note_of_frame[9], tol > 0 ? 1 : 0) << tol;
    EXPECT_EQ(a.notes[0].last_frame, tol > 0 ? 8 : 9);
    EXPECT_EQ(a.notes[1].first_frame, tol > 0 ? 9 : 10);
    for (int f = 10; f < 12; ++f) {
      EXPECT_EQ(a.frame_state[static_cast<size_t>(f)], FrameAudioState::kBoundary);
      EXPECT_EQ(a.note_of_frame[static_cast<size_t>(f)], 1);
    }
  }
  // An audio note at another pitch takes nothing.
  PitchAnalysis a = AnalysePitch(pitch, po);
  const PitchAnalysis before = a;
  ApplyAudioNoteBoundaries(
      {{0.0, 9.5 / 30, 220.0}, {9.5 / 30, 20.0 / 30, 262.0}}, 0.0, 30.0, pitch, po, {}, &a);
  EXPECT_EQ(a.note_of_frame, before.note_of_frame);
}

TEST(NoteBoundaries, AFirstFrameThatStillHearsTheChangeTakesTheNotesPitch) {
  // Notes at frames 0-9 (220 Hz) and 10-19 (247 Hz); frame 10, 7 ms after the onset, is
  // trusted but 60 cents sharp (the window straddles the change); so is frame 15, mid-note.
  const double sharp = std::exp2(60.0 / 1200.0);
  std::vector<FramePitch> pitch(20, FramePitch{220.0, 0.9});
  for (int f = 10; f < 20; ++f) pitch[static_cast<size_t>(f)].f0_hz = 247.0;
  pitch[10].f0_hz = 247.0 * sharp;
  pitch[15].f0_hz = 247.0 * sharp;
  PitchModelOptions po;
  const std::vector<AudioNote> audio = {{0.0, 9.8 / 30, 220.0}, {9.8 / 30, 20.0 / 30, 247.0}};
  for (double straddle_s : {0.0, 0.034}) {
    PitchAnalysis a = AnalysePitch(pitch, po);
    ASSERT_EQ(a.note_of_frame[10], 1);
    NoteBoundaryOptions bo;
    bo.straddle_s = straddle_s;
    ApplyAudioNoteBoundaries(audio, 0.0, 30.0, pitch, po, bo, &a);
    EXPECT_EQ(a.frame_state[10],
              straddle_s > 0 ? FrameAudioState::kBoundary : FrameAudioState::kNote);
    EXPECT_EQ(a.frame_state[15], FrameAudioState::kNote);  // vibrato or intonation: kept
    EXPECT_EQ(a.note_of_frame[10], 1);
  }
}

// The hand fit follows a lifted fingertip partly sideways (abduction): the playing tip is
// off across the string, its neighbour hovers right above its own place. Which finger
// plays is told along the string; which string by the whole hand.
TEST(ArcoEmission, ALateralTipErrorDoesNotMoveTheFingerToItsNeighbour) {
  const std::vector<SceneNote> notes = {
      {2, 1, 2, 10}, {2, 3, 6, 10}, {2, 4, 7, 10}, {2, 2, 4, 10}, {2, 3, 6, 10}, {1, 4, 7, 10}};
  testing::SceneOptions so;
  so.lift_mm = 20;
  so.lift_across_mm = 15;
  testing::Scene scene = testing::MakeScene(InstrumentKind::kViolin, notes, so);
  scene.input.audio_notes = testing::AudioNotesOf(*scene.model, notes, 30.0, 1.0 / 120.0);
  const Score s = Identification(scene, Refine(scene.input, Arco()));
  EXPECT_EQ(s.right, s.pressed);
  // Weighting the tip's own offsets like the distance along the string (the previous
  // emission) picks a neighbouring finger for some notes.
  RefineOptions old = Arco();
  old.decode.lateral_weight = 1.0;
  old.decode.normal_weight = 0.5;
  old.decode.hand_lateral_weight = 0.0;
  const Score o = Identification(scene, Refine(scene.input, old));
  EXPECT_LT(o.right, o.pressed - 20);
}

// A fingertip under the string plane is beside the fingerboard, not on the string: its
// depth beyond below_margin_mm counts in full, while a tip as far above (the detector's
// lift) counts at normal_weight. On SPD's real take the little finger curled 18-29 mm
// under the strings tied with the ring finger that played (real_take_behind4_cli_test).
TEST(ArcoEmission, ATipUnderTheStringsCountsItsDepthInFull) {
  StringFrame sf;  // along +x, normal +z (away from the fingerboard)
  const Eigen::Vector3d contact(100, 0, 0);
  hand::HandPointsMm points;
  for (auto& p : points) p = Eigen::Vector3d(0, 0, 500);  // other tips far away along z
  const int little = hand::TipKeypoint(hand::Finger::kLittle);
  ArcoDecodeOptions o;
  double d = 0, order = 0;
  points[little] = contact + Eigen::Vector3d(0, 0, 25);  // lifted 25 mm
  FrameCosts(points, sf, contact, 4, o, &d, &order);
  EXPECT_NEAR(d, std::hypot(o.normal_weight * 25, o.hand_lateral_weight * 0), 1e-9);
  points[little] = contact + Eigen::Vector3d(0, 0, -25);  // 25 mm under the strings
  FrameCosts(points, sf, contact, 4, o, &d, &order);
  EXPECT_NEAR(d, std::hypot(o.normal_weight * 25, 25 - o.below_margin_mm), 1e-9);
  points[little] = contact + Eigen::Vector3d(0, 0, -8);  // within the margin: as above it
  FrameCosts(points, sf, contact, 4, o, &d, &order);
  EXPECT_NEAR(d, o.normal_weight * 8, 1e-9);
  ArcoDecodeOptions off = o;
  off.below_margin_mm = 1e6;
  points[little] = contact + Eigen::Vector3d(0, 0, -25);
  FrameCosts(points, sf, contact, 4, off, &d, &order);
  EXPECT_NEAR(d, o.normal_weight * 25, 1e-9);
  EXPECT_FALSE([] {
    ArcoDecodeOptions bad;
    bad.below_margin_mm = -1;
    return bad.Validate().ok();
  }());
}

// The fitted hand lags a fast shift: along one note the fitted wrist trails by 12 mm (the
// whole-hand shift takes up about 11), on one frame by 22 mm (beyond the shift alone).
TEST(ArcoIk, ARejectedFrameStartsFromItsNeighboursHandShift) {
  const std::vector<SceneNote> notes = {{2, 1, 2, 20}, {2, 1, 5, 20}, {2, 3, 7, 20}};
  testing::Scene scene = testing::MakeScene(InstrumentKind::kCello, notes);
  for (int f = 20; f < 40; ++f) {
    const Eigen::Vector3d toward_nut =
        scene.world_from_instrument[static_cast<size_t>(f)].rotation.col(0);
    scene.input.vision_hand[static_cast<size_t>(f)]->world_from_wrist.translation -=
        (f == 30 ? 22.0 : 12.0) * toward_nut;
  }
  // The flexion chain only: with the MCP's abduction free too, frame 30's finger comes
  // within the hand's move on its own and needs no neighbour.
  RefineOptions flexion = Arco();
  flexion.ik.joints = hand::FingerIkJoints::kMcpFlexPipDip;
  // With the move applied to the hand (ArcoIkOptions::move_hand), the tip reaches.
  RefineOptions moved = flexion;
  moved.ik.move_hand = true;
  const RefineResult r = Refine(scene.input, moved);
  const FrameContact& c = r.contacts[30];
  EXPECT_TRUE(c.pressed());
  EXPECT_EQ(c.reason, ContactReason::kHandShifted);
  EXPECT_EQ(c.finger, 1);
  EXPECT_LT(c.tip_distance_refined_mm, 3.0);
  EXPECT_LT((c.point_in_world_mm - scene.truth_contact[30]).norm(), 1e-6);
  EXPECT_EQ(r.summary.joint_limit_violations, 0);
  // By default the same decision, and every hand stays where the fit put it (the frame 30
  // path solves the finger from the fitted hand).
  const RefineResult d = Refine(scene.input, flexion);
  EXPECT_TRUE(d.contacts[30].pressed());
  EXPECT_EQ(d.contacts[30].reason, ContactReason::kHandShifted);
  EXPECT_EQ(d.contacts[30].finger, 1);
  EXPECT_GT(d.contacts[30].tip_distance_refined_mm, 3.0);
  for (size_t f = 0; f < d.hand.size(); ++f) {
    if (!d.hand[f]) continue;
    EXPECT_EQ(d.hand[f]->world_from_wrist.translation,
              scene.input.vision_hand[f]->world_from_wrist.translation)
        << "frame " << f;
  }
  RefineOptions off = flexion;
  off.ik.neighbour_shift_frames = 0;
  const RefineResult o = Refine(scene.input, off);
  EXPECT_EQ(o.contacts[30].reason, ContactReason::kOutOfReach);
  for (int f = 20; f < 40; ++f) {
    if (f == 30) continue;
    EXPECT_TRUE(o.contacts[static_cast<size_t>(f)].pressed()) << "frame " << f;
  }
}

TEST(NoteBoundaries, ResultsDoNotDependOnTheThreadCount) {
  int short_first = -1;
  const testing::Scene scene = BlurredFastPassage(&short_first);
  const RefineResult one = Refine(scene.input, Arco(1));
  for (int threads : {2, 3, 8}) {
    const RefineResult many = Refine(scene.input, Arco(threads));
    for (size_t f = 0; f < one.hand.size(); ++f) {
      ASSERT_EQ(one.hand[f].has_value(), many.hand[f].has_value());
      if (one.hand[f]) {
        EXPECT_EQ(one.hand[f]->angles_rad, many.hand[f]->angles_rad);
        EXPECT_EQ(one.hand[f]->world_from_wrist.translation,
                  many.hand[f]->world_from_wrist.translation);
      }
      EXPECT_EQ(one.contacts[f].reason, many.contacts[f].reason);
    }
  }
}

TEST(NoteBoundaries, InvalidAudioNotesAreRejected) {
  int short_first = -1;
  testing::Scene scene = BlurredFastPassage(&short_first);
  scene.input.audio_notes[2].onset_s = scene.input.audio_notes[1].onset_s - 0.1;
  EXPECT_THROW(Refine(scene.input, Arco()), std::invalid_argument);
  scene.input.audio_notes[2].onset_s = NAN;
  EXPECT_THROW(Refine(scene.input, Arco()), std::invalid_argument);
  RefineOptions bad = Arco();
  bad.decode.boundaries.onset_tolerance_s = -1;
  EXPECT_THROW(Refine(BlurredFastPassage(&short_first).input, bad), std::invalid_argument);
}

}  // namespace
}  // namespace arco::refine
