#include "arco/eval/metrics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace arco::eval {
namespace {

// A straight left hand along +y from the wrist at `origin`, fingers fanned in x.
PointSequence MakeTruth(int frames) {
  PointSequence s(frames, 142);
  for (int f = 0; f < frames; ++f) {
    for (int p = 0; p < 142; ++p) s.set(f, p, Eigen::Vector3d(p, 2.0 * p, f));
    const Eigen::Vector3d wrist(100, 200, 300 + f);
    s.set(f, kLeftHandFirst, wrist);
    for (int finger = 0; finger < 5; ++finger) {
      for (int j = 0; j < 4; ++j) {
        s.set(f,
              kLeftHandFirst + HandJoint(finger, j),
              wrist + Eigen::Vector3d(-20.0 * finger, 60.0 + 25.0 * j, 0));
      }
    }
  }
  return s;
}

ContactTrack MakeContact(int frames) {
  ContactTrack c;
  for (int f = 0; f < frames; ++f) {
    const bool pressed = f % 2 == 0;
    c.string.push_back(pressed ? 2 : 0);
    c.finger.push_back(pressed ? 1 : 0);
    c.point_mm.push_back(pressed ? Eigen::Vector3d(100 - 20, 200 + 60 + 75, 300 + f)
                                 : Eigen::Vector3d::Constant(NAN));
  }
  return c;
}

TEST(EvaluateMethod, TruthAgainstItselfGivesZeros) {
  const PointSequence truth = MakeTruth(4);
  const ContactTrack contact = MakeContact(4);
  EvalOptions o;
  o.num_instrument_points = 9;
  const MethodMetrics m = EvaluateMethod("truth", truth, contact, truth, &contact, o);
  EXPECT_EQ(m.frames, 4);
  EXPECT_EQ(m.contact_frames, 2);
  EXPECT_EQ(m.mpjpe_hand_mm, 0.0);
  EXPECT_EQ(m.mpjpe_note_finger_mm, 0.0);
  EXPECT_EQ(m.contact_deviation_mm, 0.0);
  EXPECT_EQ(m.mpjpe_body_mm, 0.0);
  EXPECT_EQ(m.instrument_error_mm, 0.0);
  EXPECT_EQ(m.string_accuracy, 1.0);
  EXPECT_EQ(m.finger_accuracy, 1.0);
  for (double p : m.pck) EXPECT_EQ(p, 1.0);
  EXPECT_EQ(m.missing_hand_fraction, 0.0);
}

TEST(EvaluateMethod, WristAlignmentRemovesAWholeHandTranslation) {
  const PointSequence truth = MakeTruth(3);
  PointSequence moved = truth;
  for (int f = 0; f < 3; ++f) {
    for (int k = 0; k < kNumHand; ++k) {
      moved.set(
          f, kLeftHandFirst + k, truth.at(f, kLeftHandFirst + k) + Eigen::Vector3d(30, 40, 0));
    }
  }
  const ContactTrack contact = MakeContact(3);
  const MethodMetrics m = EvaluateMethod("moved", truth, contact, moved, nullptr, {});
  EXPECT_NEAR(m.mpjpe_hand_mm, 0.0, 1e-12);
  EXPECT_NEAR(m.mpjpe_note_finger_mm, 0.0, 1e-12);
  // Contact deviation is absolute: the tip is 50 mm (3-4-5) off the contact point.
  EXPECT_NEAR(m.contact_deviation_mm, 50.0, 1e-12);
  // Whole body: 21 of 133 points off by 50 mm.
  EXPECT_NEAR(m.mpjpe_body_mm, 50.0 * 21 / 133, 1e-9);
  EXPECT_TRUE(std::isnan(m.string_accuracy));  // no contact annotation
}

TEST(EvaluateMethod, HandComputedFingerErrorsAndPck) {
  const PointSequence truth = MakeTruth(2);
  PointSequence r = truth;
  // Frame 0 (pressed, index finger): index tip 8 mm off, middle tip 15 mm off.
  const int index_tip = kLeftHandFirst + HandJoint(1, 3);
  const int middle_tip = kLeftHandFirst + HandJoint(2, 3);
  r.set(0, index_tip, truth.at(0, index_tip) + Eigen::Vector3d(0, 0, 8));
  r.set(0, middle_tip, truth.at(0, middle_tip) + Eigen::Vector3d(15, 0, 0));
  // Frame 1 (not pressed): little tip 30 mm off; it must not enter contact metrics.
  const int little_tip = kLeftHandFirst + HandJoint(4, 3);
  r.set(1, little_tip, truth.at(1, little_tip) + Eigen::Vector3d(0, 30, 0));
  ContactTrack contact = MakeContact(2);
  ContactTrack guess = contact;
  guess.string[0] = 3;  // wrong string, right finger
  const MethodMetrics m = EvaluateMethod("r", truth, contact, r, &guess, {});
  EXPECT_NEAR(m.mpjpe_hand_mm, (8.0 + 15.0 + 30.0) / 40.0, 1e-12);
  EXPECT_NEAR(m.mpjpe_note_finger_mm, 8.0 / 4.0, 1e-12);
  EXPECT_NEAR(m.contact_deviation_mm, 8.0, 1e-12);
  ASSERT_EQ(m.pck.size(), 3u);
  EXPECT_NEAR(m.pck[0], 37.0 / 40.0, 1e-12);  // <= 5 mm
  EXPECT_NEAR(m.pck[1], 38.0 / 40.0, 1e-12);  // <= 10 mm
  EXPECT_NEAR(m.pck[2], 39.0 / 40.0, 1e-12);  // <= 20 mm
  EXPECT_EQ(m.string_accuracy, 0.0);
  EXPECT_EQ(m.finger_accuracy, 1.0);
}

TEST(EvaluateMethod, MissingPointsAreCountedNotAveraged) {
  const PointSequence truth = MakeTruth(1);
  PointSequence r = truth;
  r.set(0, kLeftHandFirst + 5, Eigen::Vector3d::Constant(NAN));
  const MethodMetrics m = EvaluateMethod("r", truth, MakeContact(1), r, nullptr, {});
  EXPECT_EQ(m.mpjpe_hand_mm, 0.0);
  EXPECT_NEAR(m.missing_hand_fraction, 1.0 / 20.0, 1e-12);
  PointSequence short_result(2, 142);
  EXPECT_THROW(EvaluateMethod("x", truth, MakeContact(1), short_result, nullptr, {}),
               std::invalid_argument);
}

TEST(HandFlexionDeg, SignedBendTowardsThePalm) {
  // Left hand frame: +y distal, +z palmar, x = y cross z; the thumb side is -x,
  // so index MCP at -x and little MCP at +x.
  Eigen::Vector3d hand[kNumHand];
  for (int f = 0; f < 5; ++f) {
    const double x = (f == 0) ? -40 : 15.0 * (f - 2);  // middle finger on the y axis
    for (int j = 0; j < 4; ++j) hand[HandJoint(f, j)] = Eigen::Vector3d(x, 80.0 + 30 * j, 0);
  }
  hand[0].setZero();
  // Bend the index DIP 30 degrees towards the palm (+z).
  const Eigen::Vector3d dip = hand[HandJoint(1, 2)];
  hand[HandJoint(1, 3)] = dip + 30.0 * Eigen::Vector3d(0, std::cos(M_PI / 6), std::sin(M_PI / 6));
  // Hyperextend the middle PIP by 10 degrees (towards -z); DIP stays straight relative.
  const Eigen::Vector3d pip = hand[HandJoint(2, 1)];
  const Eigen::Vector3d dir(0, std::cos(M_PI / 18), -std::sin(M_PI / 18));
  hand[HandJoint(2, 2)] = pip + 30.0 * dir;
  hand[HandJoint(2, 3)] = hand[HandJoint(2, 2)] + 30.0 * dir;
  double a[5][2];
  HandFlexionDeg(hand, /*left=*/true, a);
  EXPECT_NEAR(a[1][0], 0.0, 1e-9);
  EXPECT_NEAR(a[1][1], 30.0, 1e-9);
  EXPECT_NEAR(a[2][0], -10.0, 1e-9);
  EXPECT_NEAR(a[2][1], 0.0, 1e-9);
  // The same points read as a right hand flip the sign.
  HandFlexionDeg(hand, /*left=*/false, a);
  EXPECT_NEAR(a[1][1], -30.0, 1e-9);

  PointSequence s(1, 133);
  for (int k = 0; k < kNumHand; ++k) s.set(0, kLeftHandFirst + k, hand[k]);
  HandJointLimitsDeg limits;
  for (int f = 0; f < 5; ++f) {
    limits.min_deg[f][0] = limits.min_deg[f][1] = -5;
    limits.max_deg[f][0] = limits.max_deg[f][1] = 100;
  }
  EXPECT_EQ(CountJointLimitViolations(s, kLeftHandFirst, true, limits, 2.0), 1);  // -10 < -7
  EXPECT_EQ(CountJointLimitViolations(s, kLeftHandFirst, true, limits, 6.0), 0);
}

TEST(EvaluatePitch, HandComputedAccuracyAndVoicing) {
  const double a = 220.0;
  const double c30 = a * std::pow(2.0, 30.0 / 1200);
  const double c10 = a * std::pow(2.0, 10.0 / 1200);
  const double oct = 2 * a;
  // truth: 5 voiced, 2 unvoiced.
  const std::vector<double> truth = {a, a, a, a, a, 0, 0};
  const std::vector<double> est = {a, c10, c30, oct, 0, 0, 300};
  const PitchMetrics m = EvaluatePitch(truth, est);
  EXPECT_EQ(m.truth_voiced_frames, 5);
  EXPECT_NEAR(m.rpa50, 3.0 / 5, 1e-12);
  EXPECT_NEAR(m.rpa25, 2.0 / 5, 1e-12);
  EXPECT_NEAR(m.voicing_recall, 4.0 / 5, 1e-12);
  EXPECT_NEAR(m.voicing_false_alarm, 1.0 / 2, 1e-12);
  EXPECT_NEAR(m.median_abs_cents, 20.0, 1e-9);
  const PitchMetrics self = EvaluatePitch(truth, truth);
  EXPECT_EQ(self.rpa50, 1.0);
  EXPECT_EQ(self.voicing_false_alarm, 0.0);
  EXPECT_EQ(self.median_abs_cents, 0.0);
  EXPECT_THROW(EvaluatePitch({1.0}, {}), std::invalid_argument);
  // Leaving out the octave error and the false alarm.
  const std::vector<bool> scored = {true, true, true, false, true, true, false};
  const PitchMetrics masked = EvaluatePitch(truth, est, &scored);
  EXPECT_EQ(masked.frames, 5);
  EXPECT_NEAR(masked.rpa50, 3.0 / 4, 1e-12);
  EXPECT_NEAR(masked.voicing_false_alarm, 0.0, 1e-12);
}

TEST(ScoreDoubleStops, BothNotesInEitherVoiceOrderOverDoubleStopFramesOnly) {
  auto voices = [](int s1, int f1, int s2, int f2) {
    FrameVoices v;
    v.string[0] = s1;
    v.finger[0] = f1;
    v.string[1] = s2;
    v.finger[1] = f2;
    return v;
  };
  // Frames: single note, then four double stops (G string 3rd finger + D string open).
  const std::vector<FrameVoices> truth = {voices(4, 1, 0, 0),
                                          voices(4, 3, 3, 0),
                                          voices(4, 3, 3, 0),
                                          voices(4, 3, 3, 0),
                                          voices(4, 3, 3, 0)};
  const std::vector<FrameVoices> method = {
      voices(2, 2, 0, 0),   // wrong, but not a double-stop frame
      voices(4, 3, 3, 0),   // right
      voices(3, 0, 4, 3),   // right, voices swapped
      voices(4, 2, 3, 0),   // strings right, finger wrong
      voices(4, 3, 0, 0)};  // no second note
  MethodMetrics m;
  ScoreDoubleStops(truth, &method, &m);
  EXPECT_TRUE(m.double_stop_truth);
  EXPECT_EQ(m.double_stop_frames, 4);
  EXPECT_DOUBLE_EQ(m.double_stop_string_accuracy, 3.0 / 4);
  EXPECT_DOUBLE_EQ(m.double_stop_finger_accuracy, 2.0 / 4);
  EXPECT_EQ(m.false_double_stop_frames, 0);  // frame 0: one voice, if the wrong one
  // A second voice where the truth has one note is a false double stop.
  std::vector<FrameVoices> extra = method;
  extra[0] = voices(2, 2, 1, 1);
  MethodMetrics e;
  ScoreDoubleStops(truth, &extra, &e);
  EXPECT_EQ(e.false_double_stop_frames, 1);
  EXPECT_DOUBLE_EQ(e.double_stop_string_accuracy, 3.0 / 4);
  // No second voice from the method: NaN, never 0; no double stops in the truth: unset.
  MethodMetrics none;
  ScoreDoubleStops(truth, nullptr, &none);
  EXPECT_TRUE(none.double_stop_truth);
  EXPECT_TRUE(std::isnan(none.double_stop_string_accuracy));
  EXPECT_TRUE(std::isnan(none.double_stop_finger_accuracy));
  EXPECT_EQ(none.false_double_stop_frames, -1);
  MethodMetrics single;
  const std::vector<FrameVoices> single_truth = {voices(4, 1, 0, 0)};
  const std::vector<FrameVoices> single_method = {voices(4, 1, 0, 0)};
  ScoreDoubleStops(single_truth, &single_method, &single);
  EXPECT_FALSE(single.double_stop_truth);
  EXPECT_TRUE(std::isnan(single.double_stop_string_accuracy));
  EXPECT_THROW(ScoreDoubleStops(truth, &single_method, &m), std::invalid_argument);
}

}  // namespace
}  // namespace arco::eval
