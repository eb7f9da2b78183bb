#include "arco/hand/graft.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include "arco/hand/hand_test_util.h"

namespace arco::hand {
namespace {

// Body detector's hand = the model hand moved by a known rigid transform.
TEST(GraftHandAtWrist, RecoversAKnownRigidTransform) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::mt19937 rng(10);
  for (int trial = 0; trial < 20; ++trial) {
    const HandPose hand = testing::RandomPose(model, rng, 0.1);
    const Eigen::Matrix3d r =
        testing::RandomPose(model, rng).world_from_wrist.rotation;  // any rotation
    const Eigen::Vector3d t(300.0 * trial, -50, 80);
    HandPointsMm body = ForwardKinematics(model, hand);
    for (auto& p : body) p = r * p + t;
    const WristGraftResult g = GraftHandAtWrist(model, hand, body, {}, WristGraftOptions{});
    ASSERT_TRUE(g.ok) << g.problem;
    EXPECT_TRUE(g.moved_from_input.rotation.isApprox(r, 1e-9));
    EXPECT_LT((g.moved_from_input.translation - t).norm(), 1e-6);
    EXPECT_LT(g.rms_mm, 1e-6);
    EXPECT_EQ(g.pose.angles_rad, hand.angles_rad);
    const HandPointsMm moved = ForwardKinematics(model, g.pose);
    for (int k = 0; k < kNumHandKeypoints; ++k) EXPECT_LT((moved[k] - body[k]).norm(), 1e-6);
  }
}

TEST(GraftHandAtWrist, WeightsMissingPointsOutliersAndPinnedWrist) {
  const HandModel model = HandModel::Default(HandSide::kRight);
  std::mt19937 rng(11);
  const HandPose hand = testing::RandomPose(model, rng, 0.1);
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(10, 20, 30);
  HandPointsMm body = ForwardKinematics(model, hand);
  for (auto& p : body) p = r * p + t;
  body[4].setConstant(std::nan(""));
  body[12] += Eigen::Vector3d(0, 0, 80);  // gross detector error
  std::vector<double> weights(21, 1.0);
  weights[12] = 0.0;  // ... that its score flags
  WristGraftResult g = GraftHandAtWrist(model, hand, body, weights, WristGraftOptions{});
  ASSERT_TRUE(g.ok);
  EXPECT_TRUE(g.moved_from_input.rotation.isApprox(r, 1e-9));
  EXPECT_EQ(g.num_points, 19);
  // Same outlier with full weight but a robust loss.
  WristGraftOptions robust;
  robust.robust_loss_mm = 5;
  g = GraftHandAtWrist(model, hand, body, {}, robust);
  ASSERT_TRUE(g.ok);
  EXPECT_LT(Eigen::AngleAxisd(g.moved_from_input.rotation.transpose() * r).angle(), 0.01);
  // Pinned wrist: the model wrist lands exactly on a (shifted) body wrist.
  body[0] += Eigen::Vector3d(5, 0, 0);
  WristGraftOptions pinned;
  pinned.pin_wrist = true;
  g = GraftHandAtWrist(model, hand, body, weights, pinned);
  ASSERT_TRUE(g.ok);
  EXPECT_LT((g.pose.world_from_wrist.translation - body[0]).norm(), 1e-9);
}

TEST(GraftHandAtWrist, FlagsTooFewPoints) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  HandPointsMm body;
  body.fill(Eigen::Vector3d::Constant(std::nan("")));
  body[0] = Eigen::Vector3d(1, 2, 3);
  body[5] = Eigen::Vector3d(1, 90, 3);
  const WristGraftResult g = GraftHandAtWrist(model, HandPose{}, body, {}, WristGraftOptions{});
  EXPECT_FALSE(g.ok);
  EXPECT_EQ(g.pose.angles_rad, HandPose{}.angles_rad);
  WristGraftOptions pinned;
  pinned.pin_wrist = true;
  body[0].setConstant(std::nan(""));
  EXPECT_FALSE(GraftHandAtWrist(model, HandPose{}, body, {}, pinned).ok);
  EXPECT_THROW(GraftHandAtWrist(model, HandPose{}, body, {1.0, 2.0}, WristGraftOptions{}),
               std::invalid_argument);
}

}  // namespace
}  // namespace arco::hand
