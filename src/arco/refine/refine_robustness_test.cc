// Limits, determinism, thread independence and bad input of the refinement.
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "arco/refine/refine.h"
#include "arco/refine/test_scene.h"

namespace arco::refine {
namespace {

using testing::SceneNote;

std::vector<SceneNote> RandomPiece(std::mt19937& rng, int num_notes) {
  std::uniform_int_distribution<int> string(1, 4), finger(0, 4), semitone(1, 9), frames(4, 25);
  std::uniform_real_distribution<double> vib(0, 40);
  std::vector<SceneNote> notes;
  for (int i = 0; i < num_notes; ++i) {
    SceneNote n;
    n.string = (i % 5 == 4) ? 0 : string(rng);  // a rest now and then
    n.finger = finger(rng);
    n.semitones = n.finger > 0 ? n.finger - 1 + semitone(rng) : 0;
    n.frames = frames(rng);
    n.vibrato_cents = n.finger > 0 && n.frames > 12 ? vib(rng) : 0;
    notes.push_back(n);
  }
  return notes;
}

void ExpectSameResult(const RefineResult& a, const RefineResult& b) {
  ASSERT_EQ(a.hand.size(), b.hand.size());
  ASSERT_EQ(a.contacts.size(), b.contacts.size());
  for (size_t f = 0; f < a.hand.size(); ++f) {
    ASSERT_EQ(a.hand[f].has_value(), b.hand[f].has_value());
    if (a.hand[f]) {
      EXPECT_EQ(a.hand[f]->angles_rad, b.hand[f]->angles_rad) << "frame " << f;
      EXPECT_EQ(a.hand[f]->world_from_wrist.translation, b.hand[f]->world_from_wrist.translation);
    }
    const FrameContact& ca = a.contacts[f];
    const FrameContact& cb = b.contacts[f];
    EXPECT_EQ(ca.state, cb.state);
    EXPECT_EQ(ca.reason, cb.reason);
    EXPECT_EQ(ca.string, cb.string);
    EXPECT_EQ(ca.finger, cb.finger);
    EXPECT_EQ(ca.point_in_world_mm.allFinite(), cb.point_in_world_mm.allFinite());
    if (ca.point_in_world_mm.allFinite()) {
      EXPECT_EQ(ca.point_in_world_mm, cb.point_in_world_mm);
    }
    EXPECT_EQ(std::isnan(ca.tip_distance_refined_mm), std::isnan(cb.tip_distance_refined_mm));
    if (!std::isnan(ca.tip_distance_refined_mm)) {
      EXPECT_EQ(ca.tip_distance_refined_mm, cb.tip_distance_refined_mm);
    }
  }
  EXPECT_EQ(a.summary.ik_iterations, b.summary.ik_iterations);
}

TEST(Refine, NeverViolatesAJointLimitEvenOnHarshInput) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 3; ++trial) {
    testing::SceneOptions so;
    so.seed = 100 + trial;
    so.lift_mm = 25;
    so.angle_noise_deg = 12;  // far beyond a good fit: many angles end on their limits
    so.wrist_noise_mm = 8;
    const testing::Scene scene = testing::MakeScene(
        trial == 1 ? InstrumentKind::kViolin : InstrumentKind::kCello, RandomPiece(rng, 12), so);
    for (RefineMode mode : {RefineMode::kPaper, RefineMode::kArco}) {
      RefineOptions o;
      o.mode = mode;
      const RefineResult r = Refine(scene.input, o);
      EXPECT_EQ(r.summary.joint_limit_violations, 0);
      for (const auto& h : r.hand) {
        if (h) {
          EXPECT_EQ(hand::CountLimitViolations(scene.input.hand_model, *h, 0.0), 0);
        }
      }
      if (mode == RefineMode::kArco) {
        // By default the hand stays where the fit put it (ArcoIkOptions::move_hand) and each
        // pressed frame reports the distance its tip really ends from the contact.
        for (size_t f = 0; f < r.contacts.size(); ++f) {
          const FrameContact& c = r.contacts[f];
          if (!r.hand[f]) continue;
          EXPECT_EQ(r.hand[f]->world_from_wrist.translation,
                    scene.input.vision_hand[f]->world_from_wrist.translation);
          if (!c.pressed() || !std::isfinite(c.tip_distance_refined_mm)) continue;
          const Eigen::Vector3d tip = hand::FingertipInWorld(
              scene.input.hand_model, *r.hand[f], static_cast<hand::Finger>(c.finger));
          EXPECT_NEAR(c.tip_distance_refined_mm, (tip - c.point_in_world_mm).norm(), 1e-6);
        }
        // With the move applied: a contact the finger cannot reach even with the hand's move
        // keeps its decision (ArcoIkOptions::keep_unreachable) and says so; every other
        // reaches it.
        RefineOptions moved = o;
        moved.ik.move_hand = true;
        const RefineResult m = Refine(scene.input, moved);
        EXPECT_EQ(m.summary.joint_limit_violations, 0);
        for (const FrameContact& c : m.contacts) {
          if (!c.pressed() || !std::isfinite(c.tip_distance_refined_mm)) continue;
          if (c.reason == ContactReason::kOutOfReach) {
            EXPECT_GT(c.tip_distance_refined_mm, o.ik.max_hand_shift_mm);
          } else {
            EXPECT_LE(c.tip_distance_refined_mm, o.ik.max_residual_mm);
          }
        }
      }
    }
  }
}

TEST(Refine, ResultsDoNotDependOnTheThreadCount) {
  std::mt19937 rng(5);
  const testing::Scene scene = testing::MakeScene(InstrumentKind::kCello, RandomPiece(rng, 14));
  for (RefineMode mode : {RefineMode::kPaper, RefineMode::kArco}) {
    RefineOptions o;
    o.mode = mode;
    o.num_threads = 1;
    const RefineResult one = Refine(scene.input, o);
    for (int threads : {2, 3, 8}) {
      o.num_threads = threads;
      ExpectSameResult(one, Refine(scene.input, o));
    }
    o.num_threads = 1;
    ExpectSameResult(one, Refine(scene.input, o));  // and again: no hidden state
  }
}

TEST(Refine, FramesWithoutAHandStillGetTheirContact) {
  const std::vector<SceneNote> notes = {{2, 1, 2, 20}, {2, 3, 4, 20}};
  testing::Scene scene = testing::MakeScene(InstrumentKind::kCello, notes);
  for (int f = 5; f < 10; ++f) scene.input.vision_hand[static_cast<size_t>(f)].reset();
  for (int f = 20; f < 40; ++f) scene.input.vision_hand[static_cast<size_t>(f)].reset();
  for (RefineMode mode : {RefineMode::kPaper, RefineMode::kArco}) {
    RefineOptions o;
    o.mode = mode;
    const RefineResult r = Refine(scene.input, o);
    for (int f = 5; f < 10; ++f) {
      EXPECT_FALSE(r.hand[static_cast<size_t>(f)].has_value());
      EXPECT_TRUE(r.contacts[static_cast<size_t>(f)].pressed()) << RefineModeName(mode);
      EXPECT_EQ(r.contacts[static_cast<size_t>(f)].reason, ContactReason::kNoHand);
      EXPECT_EQ(r.contacts[static_cast<size_t>(f)].string, 2);
    }
    if (mode == RefineMode::kArco) {  // a whole note without a hand: pitch and strings only
      for (int f = 20; f < 40; ++f) {
        EXPECT_TRUE(r.contacts[static_cast<size_t>(f)].pressed());
        EXPECT_EQ(r.contacts[static_cast<size_t>(f)].string, 2);
      }
    }
  }
}

TEST(Refine, VisionModeReturnsTheFittedHandAndNoContacts) {
  const testing::Scene scene = testing::MakeScene(InstrumentKind::kCello, {{2, 1, 2, 10}});
  RefineOptions o;
  o.mode = RefineMode::kVision;
  const RefineResult r = Refine(scene.input, o);
  EXPECT_TRUE(r.contacts.empty());
  ASSERT_EQ(r.hand.size(), 10u);
  EXPECT_EQ(r.hand[3]->angles_rad, scene.input.vision_hand[3]->angles_rad);
}

TEST(Refine, InvalidInputAndOptionsThrowWithAMessage) {
  testing::Scene scene = testing::MakeScene(InstrumentKind::kCello, {{2, 1, 2, 10}});
  RefineOptions o;
  RefineInput bad = scene.input;
  bad.pitch.pop_back();
  EXPECT_THROW(Refine(bad, o), std::invalid_argument);
  bad = scene.input;
  bad.instrument = nullptr;
  EXPECT_THROW(Refine(bad, o), std::invalid_argument);
  bad = scene.input;
  bad.hand_model = hand::HandModel::Default(hand::HandSide::kRight);
  EXPECT_FALSE(bad.Validate().ok());
  bad = scene.input;
  bad.strings_in_world_mm[2].pop_back();
  EXPECT_FALSE(bad.Validate().ok());
  bad = scene.input;
  bad.fps = 0;
  EXPECT_FALSE(bad.Validate().ok());
  // Non-finite strings are a frame without strings, not an error.
  RefineInput nan_strings = scene.input;
  nan_strings.strings_in_world_mm[4][1].nut.x() = NAN;
  const RefineResult r = Refine(nan_strings, o);
  EXPECT_EQ(r.contacts[4].reason, ContactReason::kNoInstrument);

  RefineOptions ob;
  ob.paper.binding_cents = 0;
  EXPECT_FALSE(ob.Validate().ok());
  ob = {};
  ob.decode.open_cost_mm = -1;
  EXPECT_FALSE(ob.Validate().ok());
  ob = {};
  ob.ik.max_residual_mm = 0;
  EXPECT_FALSE(ob.Validate().ok());
  ob = {};
  ob.ik.temporal_weight_mm_per_rad = NAN;
  EXPECT_FALSE(ob.Validate().ok());
  ob = {};
  ob.decode.shift_cost_per_semitone = 1e300;  // huge: the sums over a clip overflow
  EXPECT_EQ(ob.Validate().message(),
            "arco decode options: shift_cost_per_semitone must be a finite number in "
            "[0, 1000000], got 1e+300");
  ob = {};
  ob.ik.reference_weight_mm_per_rad = -1;
  EXPECT_FALSE(ob.Validate().ok());
  ob = {};
  ob.num_threads = -1;
  EXPECT_FALSE(ob.Validate().ok());
  EXPECT_THROW(Refine(scene.input, ob), std::invalid_argument);
  EXPECT_FALSE(ParseRefineMode("magic").ok());
  EXPECT_EQ(*ParseRefineMode("Paper"), RefineMode::kPaper);
}

}  // namespace
}  // namespace arco::refine
