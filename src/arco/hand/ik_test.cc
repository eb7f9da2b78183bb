#include "arco/hand/ik.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>

#include "arco/hand/hand_test_util.h"
#include "arco/hand/kinematics.h"

namespace arco::hand {
namespace {

constexpr double kDeg = M_PI / 180.0;

// Reference = truth with the free dofs of `finger` re-drawn inside the limits.
HandPose PerturbFreeDofs(const HandModel& model,
                         const HandPose& truth,
                         Finger finger,
                         FingerIkJoints joints,
                         std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  HandPose ref = truth;
  for (FingerDof slot : FreeDofs(joints)) {
    const int d = DofIndex(finger, slot);
    ref.angles_rad[d] = model.min_rad(d) + u(rng) * (model.max_rad(d) - model.min_rad(d));
  }
  return ref;
}

TEST(SolveFingertipIk, ReachesReachableTargetsExactlyForEveryFingerAndMode) {
  std::mt19937 rng(42);
  double worst_mm = 0;
  int cases = 0;
  for (HandSide side : {HandSide::kLeft, HandSide::kRight}) {
    const HandModel model = HandModel::Default(side);
    for (FingerIkJoints joints :
         {FingerIkJoints::kPipDip, FingerIkJoints::kMcpFlexPipDip, FingerIkJoints::kAll}) {
      for (int f = 0; f < kNumFingers; ++f) {
        const Finger finger = static_cast<Finger>(f);
        for (int trial = 0; trial < 20; ++trial) {
          const HandPose truth = testing::RandomPose(model, rng, 0.02);
          const Eigen::Vector3d target = FingertipInWorld(model, truth, finger);
          const HandPose ref = PerturbFreeDofs(model, truth, finger, joints, rng);
          FingerIkOptions options;
          options.joints = joints;
          const FingerIkResult r = SolveFingertipIk(model, ref, finger, target, options);
          ASSERT_TRUE(r.status.ok());
          EXPECT_LT(r.final_distance_mm, 1e-3)
              << FingerName(finger) << " " << FingerIkJointsName(joints) << " trial " << trial
              << " truth dofs " << truth.angles_rad[4 * f] << " " << truth.angles_rad[4 * f + 1]
              << " " << truth.angles_rad[4 * f + 2] << " " << truth.angles_rad[4 * f + 3] << " got "
              << r.pose.angles_rad[4 * f + 2] << " " << r.pose.angles_rad[4 * f + 3] << " "
              << r.termination << " it " << r.iterations << " solves " << r.solves;
          EXPECT_NEAR(
              (FingertipInWorld(model, r.pose, finger) - target).norm(), r.final_distance_mm, 1e-9);
          EXPECT_EQ(CountLimitViolations(model, r.pose, 0.0), 0);
          // Only the free dofs of this finger move.
          std::vector<bool> free(kNumJointDofs, false);
          for (FingerDof slot : FreeDofs(joints)) free[DofIndex(finger, slot)] = true;
          for (int d = 0; d < kNumJointDofs; ++d) {
            if (!free[d]) {
              EXPECT_EQ(r.pose.angles_rad[d], ref.angles_rad[d]) << DofName(d);
            }
          }
          worst_mm = std::max(worst_mm, r.final_distance_mm);
          ++cases;
        }
      }
    }
  }
  std::printf("[ reach ] %d reachable targets, worst final distance %.2e mm\n", cases, worst_mm);
}

// Unreachable targets: the result is as close as a brute-force search over the
// two free joints inside their limits can get.
TEST(SolveFingertipIk, UnreachableTargetsEndAsCloseAsLimitsAllow) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::mt19937 rng(9);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const Finger finger = static_cast<Finger>(1 + trial % 4);
    const HandPose ref = testing::RandomPose(model, rng, 0.1);
    // A point well off the finger's reach: far out along random directions.
    const Eigen::Vector3d target = FingertipInWorld(model, ref, finger) +
                                   Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized() * 60.0;
    FingerIkOptions options;
    const FingerIkResult r = SolveFingertipIk(model, ref, finger, target, options);
    ASSERT_TRUE(r.status.ok());
    EXPECT_EQ(CountLimitViolations(model, r.pose, 0.0), 0);
    const int pip = DofIndex(finger, FingerDof::kMiddleFlex);
    const int dip = DofIndex(finger, FingerDof::kDistalFlex);
    double best = 1e9;
    HandPose probe = ref;
    const int steps = 240;
    for (int i = 0; i <= steps; ++i) {
      for (int j = 0; j <= steps; ++j) {
        probe.angles_rad[pip] =
            model.min_rad(pip) + (model.max_rad(pip) - model.min_rad(pip)) * i / steps;
        probe.angles_rad[dip] =
            model.min_rad(dip) + (model.max_rad(dip) - model.min_rad(dip)) * j / steps;
        best = std::min(best, (FingertipInWorld(model, probe, finger) - target).norm());
      }
    }
    EXPECT_LE(r.final_distance_mm, best + 1e-6) << "trial " << trial;
    EXPECT_GT(r.final_distance_mm, 1.0);  // truly unreachable
  }
}

TEST(SolveFingertipIk, TargetBehindTheFingerPinsJointsAtTheirLimits) {
  const HandModel model = HandModel::Default(HandSide::kRight);
  HandPose ref;
  ref.angle_rad(Finger::kIndex, FingerDof::kMiddleFlex) = 20 * kDeg;
  // Far on the dorsal side: the best the finger can do is full extension.
  const Eigen::Vector3d target =
      FingertipInWorld(model, ref, Finger::kIndex) + Eigen::Vector3d(0, 0, -200);
  const FingerIkResult r = SolveFingertipIk(model, ref, Finger::kIndex, target, FingerIkOptions{});
  EXPECT_EQ(CountLimitViolations(model, r.pose, 0.0), 0);
  EXPECT_FALSE(r.active_limit_dofs.empty());
  EXPECT_EQ(r.pose.angle_rad(Finger::kIndex, FingerDof::kMiddleFlex),
            model.min_rad(DofIndex(Finger::kIndex, FingerDof::kMiddleFlex)));
}

TEST(SolveFingertipIk, MaxChangeBoundsEveryStep) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::mt19937 rng(21);
  const HandPose ref = testing::RandomPose(model, rng, 0.3);
  HandPose truth = ref;
  truth.angle_rad(Finger::kMiddle, FingerDof::kMiddleFlex) += 25 * kDeg;
  const Eigen::Vector3d target = FingertipInWorld(model, truth, Finger::kMiddle);
  FingerIkOptions options;
  options.max_change_deg = 5;
  const FingerIkResult r = SolveFingertipIk(model, ref, Finger::kMiddle, target, options);
  for (FingerDof slot : FreeDofs(options.joints)) {
    EXPECT_LE(
        std::abs(r.pose.angle_rad(Finger::kMiddle, slot) - ref.angle_rad(Finger::kMiddle, slot)),
        5 * kDeg + 1e-12);
  }
  EXPECT_TRUE(r.step_limited);
  EXPECT_LT(r.final_distance_mm, r.initial_distance_mm);
}

TEST(SolveFingertipIk, PreviousPoseRegularisationPullsTowardsIt) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::mt19937 rng(4);
  const HandPose ref = testing::RandomPose(model, rng, 0.2);
  HandPose previous = ref;
  previous.angle_rad(Finger::kRing, FingerDof::kDistalFlex) += 20 * kDeg;
  // Unreachable target straight out from the tip: only the regularisers decide.
  const Eigen::Vector3d target = FingertipInWorld(model, ref, Finger::kRing);
  FingerIkOptions options;
  options.exact_reach = false;
  options.restarts = 0;
  options.reference_weight_mm_per_rad = 1.0;
  options.previous_pose = previous;
  options.previous_weight_mm_per_rad = 100.0;
  const FingerIkResult r = SolveFingertipIk(model, ref, Finger::kRing, target, options);
  const double moved = r.pose.angle_rad(Finger::kRing, FingerDof::kDistalFlex) -
                       ref.angle_rad(Finger::kRing, FingerDof::kDistalFlex);
  EXPECT_GT(moved, 10 * kDeg);  // the strong temporal prior wins over the reach term
}

TEST(SolveFingertipIk, BadInputGivesStatusAndAPoseWithinLimits) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  HandPose ref;
  ref.angle_rad(Finger::kIndex, FingerDof::kMiddleFlex) = 3.0;  // beyond 110 deg
  ref.angle_rad(Finger::kIndex, FingerDof::kBaseAbd) = std::nan("");
  const FingerIkResult nan_target = SolveFingertipIk(
      model, ref, Finger::kIndex, Eigen::Vector3d(std::nan(""), 0, 0), FingerIkOptions{});
  EXPECT_FALSE(nan_target.status.ok());
  EXPECT_EQ(CountLimitViolations(model, nan_target.pose), 0);
  EXPECT_EQ(nan_target.clamped_reference_dofs, 2);

  const FingerIkResult ok =
      SolveFingertipIk(model, ref, Finger::kIndex, Eigen::Vector3d(0, 150, 0), FingerIkOptions{});
  EXPECT_TRUE(ok.status.ok());
  EXPECT_EQ(CountLimitViolations(model, ok.pose, 0.0), 0);

  HandPose bad_wrist;
  bad_wrist.world_from_wrist.translation.x() = INFINITY;
  EXPECT_FALSE(
      SolveFingertipIk(model, bad_wrist, Finger::kIndex, Eigen::Vector3d::Zero(), FingerIkOptions{})
          .status.ok());
}

TEST(SolveFingertipIk, LockedJointStaysFixed) {
  JointLimitsDeg limits = DefaultJointLimitsDeg();
  limits[DofIndex(Finger::kIndex, FingerDof::kDistalFlex)] = {10, 10};
  const HandModel model =
      HandModel::Create(HandSide::kRight, DefaultRightRestPointsMm(), limits).value();
  HandPose ref = ClampToLimits(model, HandPose{});
  HandPose truth = ref;
  truth.angle_rad(Finger::kIndex, FingerDof::kMiddleFlex) = 40 * kDeg;
  const FingerIkResult r = SolveFingertipIk(model,
                                            ref,
                                            Finger::kIndex,
                                            FingertipInWorld(model, truth, Finger::kIndex),
                                            FingerIkOptions{});
  EXPECT_LT(r.final_distance_mm, 1e-3);
  EXPECT_EQ(r.pose.angle_rad(Finger::kIndex, FingerDof::kDistalFlex), 10 * kDeg);
}

TEST(SolveFingertipIk, DeterministicBitForBit) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::mt19937 rng(8);
  const HandPose ref = testing::RandomPose(model, rng, 0.1);
  const Eigen::Vector3d target =
      FingertipInWorld(model, ref, Finger::kIndex) + Eigen::Vector3d(5, -7, 3);
  FingerIkOptions options;
  options.joints = FingerIkJoints::kAll;
  const FingerIkResult a = SolveFingertipIk(model, ref, Finger::kIndex, target, options);
  const FingerIkResult b = SolveFingertipIk(model, ref, Finger::kIndex, target, options);
  EXPECT_EQ(a.pose.angles_rad, b.pose.angles_rad);
  EXPECT_EQ(a.iterations, b.iterations);
}

TEST(FingerIkOptions, ValidateRejectsBadValues) {
  FingerIkOptions o;
  EXPECT_TRUE(o.Validate().ok());
  o.reference_weight_mm_per_rad = -1;
  EXPECT_FALSE(o.Validate().ok());
  o = FingerIkOptions{};
  o.max_change_deg = 0;
  EXPECT_FALSE(o.Validate().ok());
  o = FingerIkOptions{};
  o.seed_levels = 1;
  EXPECT_FALSE(o.Validate().ok());
  o = FingerIkOptions{};
  o.max_iterations = 0;
  EXPECT_FALSE(o.Validate().ok());
  const HandModel model = HandModel::Default(HandSide::kLeft);
  EXPECT_THROW(SolveFingertipIk(model, HandPose{}, Finger::kIndex, Eigen::Vector3d::Zero(), o),
               std::invalid_argument);
}

// A joint observation (FingerIkOptions::pip_/dip_target_in_world_mm) over 10 random poses
// of each finger: a tip target reached with every joint free, once without and once with
// the keypoint `slot` (1: PIP, 2: DIP) held at the truth's place, the observation; the
// reference's is off.
struct HeldJointTrials {
  double with_mm = 0, without_mm = 0;      // sums of the joint's distance from where it was seen
  double tip_mean_mm = 0, tip_max_mm = 0;  // with the observation: tip to target
  int cases = 0;
};

HeldJointTrials TryHeldJoint(int slot, unsigned seed) {
  std::mt19937 rng(seed);
  const HandModel model = HandModel::Default(HandSide::kLeft);
  HeldJointTrials t;
  for (int f = 1; f < kNumFingers; ++f) {
    const Finger finger = static_cast<Finger>(f);
    for (int trial = 0; trial < 10; ++trial) {
      const HandPose truth = testing::RandomPose(model, rng, 0.02);
      const Eigen::Vector3d target = FingertipInWorld(model, truth, finger);
      const HandPose ref = PerturbFreeDofs(model, truth, finger, FingerIkJoints::kAll, rng);
      const int joint = KeypointIndex(finger, slot);
      const Eigen::Vector3d seen = ForwardKinematics(model, truth)[joint];
      FingerIkOptions without;
      without.joints = FingerIkJoints::kAll;
      without.exact_reach = false;
      FingerIkOptions with = without;
      (slot == 1 ? with.pip_target_in_world_mm : with.dip_target_in_world_mm) = seen;
      (slot == 1 ? with.pip_weight : with.dip_weight) = 1.0;
      const FingerIkResult a = SolveFingertipIk(model, ref, finger, target, without);
      const FingerIkResult b = SolveFingertipIk(model, ref, finger, target, with);
      EXPECT_TRUE(a.status.ok());
      EXPECT_TRUE(b.status.ok());
      EXPECT_EQ(CountLimitViolations(model, b.pose, 0.0), 0);
      t.tip_mean_mm += b.final_distance_mm;
      t.tip_max_mm = std::max(t.tip_max_mm, b.final_distance_mm);
      t.with_mm += (ForwardKinematics(model, b.pose)[joint] - seen).norm();
      t.without_mm += (ForwardKinematics(model, a.pose)[joint] - seen).norm();
      ++t.cases;
    }
  }
  t.tip_mean_mm /= t.cases;
  return t;
}

// The PIP observation: with it the solution's PIP ends nearer the truth's, and every tip
// still comes near its target.
TEST(SolveFingertipIk, APipObservationHoldsThePipWhereItWasSeen) {
  const HeldJointTrials t = TryHeldJoint(1, 7);
  std::printf(
      "[ ik ] PIP from where it was seen, mean over %d: with the observation %.2f mm, "
      "without %.2f mm\n",
      t.cases,
      t.with_mm / t.cases,
      t.without_mm / t.cases);
  EXPECT_LT(t.with_mm, 0.5 * t.without_mm);
  EXPECT_LT(t.tip_max_mm, 3.0);
  // A weight or an observation that cannot be used is refused.
  FingerIkOptions bad;
  bad.pip_weight = -1;
  EXPECT_FALSE(bad.Validate().ok());
  bad.pip_weight = 1;
  bad.pip_target_in_world_mm = Eigen::Vector3d(NAN, 0, 0);
  EXPECT_FALSE(bad.Validate().ok());
}

// The DIP observation, as the PIP's, with the distal joints free (the DIP keypoint moves
// with the PIP's flexion): held at the truth's DIP, the solution's DIP ends nearer it, and
// the tips still come near their targets on average.
TEST(SolveFingertipIk, ADipObservationHoldsTheDipWhereItWasSeen) {
  const HeldJointTrials t = TryHeldJoint(2, 11);
  std::printf(
      "[ ik ] DIP from where it was seen, mean over %d: with the observation %.2f mm, "
      "without %.2f mm; tip %.2f mm from its target\n",
      t.cases,
      t.with_mm / t.cases,
      t.without_mm / t.cases,
      t.tip_mean_mm);
  EXPECT_LT(t.with_mm, 0.5 * t.without_mm);
  EXPECT_LT(t.tip_mean_mm, 3.0);
  FingerIkOptions bad;
  bad.dip_weight = -1;
  EXPECT_FALSE(bad.Validate().ok());
  bad.dip_weight = 1;
  bad.dip_target_in_world_mm = Eigen::Vector3d(0, NAN, 0);
  EXPECT_FALSE(bad.Validate().ok());
}

}  // namespace
}  // namespace arco::hand

namespace arco::hand {
namespace {

// The restart grid's shared-prefix scores are each point's own tip distance, bit for bit
// (so the restarts chosen are those of evaluating every point).
TEST(SolveFingertipIk, RestartGridScoresAreEachPointsOwnTipDistance) {
  std::mt19937 rng(7);
  const HandModel model = HandModel::Default(HandSide::kLeft);
  int points = 0;
  for (FingerIkJoints joints :
       {FingerIkJoints::kPipDip, FingerIkJoints::kMcpFlexPipDip, FingerIkJoints::kAll}) {
    for (int f = 0; f < kNumFingers; ++f) {
      const Finger finger = static_cast<Finger>(f);
      const HandPose pose = testing::RandomPose(model, rng, 0.3);
      std::array<double, 4> reference;
      for (int i = 0; i < 4; ++i) reference[i] = pose.angles_rad[4 * f + i];
      std::vector<int> slots;
      std::vector<double> lower, upper;
      for (FingerDof slot : FreeDofs(joints)) {
        const int d = DofIndex(finger, slot);
        if (!(model.max_rad(d) > model.min_rad(d))) continue;
        slots.push_back(static_cast<int>(slot));
        lower.push_back(model.min_rad(d));
        upper.push_back(model.max_rad(d));
      }
      const int levels = 5;
      const Eigen::Vector3d target(10.0, -40.0, 75.0);
      const std::vector<double> grid =
          internal::RestartGridTipDistances(model,
                                            finger,
                                            reference,
                                            slots,
                                            lower,
                                            upper,
                                            levels,
                                            pose.world_from_wrist.rotation,
                                            pose.world_from_wrist.translation,
                                            target);
      int combos = 1;
      for (size_t i = 0; i < slots.size(); ++i) combos *= levels;
      ASSERT_EQ(grid.size(), static_cast<size_t>(combos));
      for (int c = 0; c < combos; ++c) {
        std::array<double, 4> dof = reference;
        for (size_t i = 0, rest = c; i < slots.size(); ++i, rest /= levels) {
          dof[slots[i]] = lower[i] + (upper[i] - lower[i]) * (rest % levels) / (levels - 1.0);
        }
        Eigen::Vector3d p[4];
        FingerPointsInWrist(model, finger, dof.data(), p);
        const double own =
            (pose.world_from_wrist.rotation * p[3] + pose.world_from_wrist.translation - target)
                .norm();
        ASSERT_EQ(grid[c], own) << FingerName(finger) << " " << FingerIkJointsName(joints)
                                << " point " << c;
        ++points;
      }
    }
  }
  EXPECT_GT(points, 100);
}

}  // namespace
}  // namespace arco::hand
