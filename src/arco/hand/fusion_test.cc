#include "arco/hand/fusion.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>

#include "arco/hand/hand_test_util.h"
#include "arco/hand/synthetic_rig.h"
#include "arco/testing/look_at.h"

namespace arco::hand {
namespace {

constexpr double kDeg = M_PI / 180.0;

// Per-view 3D hands: the truth in each camera's frame, scaled (detector size
// error), with noise growing for views that see the palm edge-on.
std::vector<ViewHand3d> MakeViewHands(const HandModel& model,
                                      const HandPose& truth,
                                      const std::vector<Camera>& cameras,
                                      std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const HandPointsMm world = ForwardKinematics(model, truth);
  const Eigen::Vector3d palm_normal =
      (world[5] - world[0]).cross(world[17] - world[0]).normalized();
  std::vector<ViewHand3d> views(cameras.size());
  for (size_t v = 0; v < cameras.size(); ++v) {
    const Camera& c = cameras[v];
    const Eigen::Vector3d to_camera = (c.CenterInWorld() - world[0]).normalized();
    const double cosine = std::abs(palm_normal.dot(to_camera));
    const double noise_mm = 1.0 + 6.0 * (1.0 - cosine);  // edge-on views are noisier
    const double scale = 0.9 + 0.2 * u(rng);
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      views[v].points_in_camera_mm[k] = c.PointInCamera(world[0]) +
                                        scale * c.cam_from_world.rotation * (world[k] - world[0]) +
                                        noise_mm * Eigen::Vector3d(n(rng), n(rng), n(rng));
    }
    views[v].confidence = 0.6 + 0.4 * u(rng);
  }
  return views;
}

double WristFrameMpjpe(const HandModel& model, const HandPose& a, const HandPose& b) {
  const HandPointsMm pa = ForwardKinematicsInWrist(model, a),
                     pb = ForwardKinematicsInWrist(model, b);
  double sum = 0;
  for (int k = 0; k < kNumHandKeypoints; ++k) sum += (pa[k] - pb[k]).norm();
  return sum / kNumHandKeypoints;
}

TEST(FuseViewHands, RecoversJointAnglesFromNoisyPerViewHands) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  const std::vector<Camera> cameras = testing::MakeRingRig(12, 2500, Eigen::Vector3d::Zero());
  std::mt19937 rng(31);
  double mean_mm = 0, mean_rot_deg = 0, mean_single_mm = 0;
  const int trials = 10;
  for (int trial = 0; trial < trials; ++trial) {
    HandPose truth = testing::RandomPose(model, rng, 0.1);
    truth.world_from_wrist.translation.setZero();
    const std::vector<ViewHand3d> views = MakeViewHands(model, truth, cameras, rng);
    const FusedHand fused = FuseViewHands(model, cameras, views, HandFusionOptions{});
    ASSERT_TRUE(fused.ok) << fused.problem;
    EXPECT_EQ(fused.num_views_used, 12);
    EXPECT_EQ(CountLimitViolations(model, fused.pose, 0.0), 0);
    EXPECT_EQ(fused.pose.world_from_wrist.translation, Eigen::Vector3d::Zero());
    mean_mm += WristFrameMpjpe(model, fused.pose, truth) / trials;
    const Eigen::Matrix3d d =
        fused.pose.world_from_wrist.rotation.transpose() * truth.world_from_wrist.rotation;
    mean_rot_deg += Eigen::AngleAxisd(d).angle() / kDeg / trials;
    // Baseline: one view alone (the first), fitted the same way.
    const FusedHand single = FuseViewHands(model, {cameras[0]}, {views[0]}, HandFusionOptions{});
    mean_single_mm += WristFrameMpjpe(model, single.pose, truth) / trials;
  }
  std::printf(
      "[ fusion ] 12 views, 1-7 mm noise by view angle, +-10%% scale: wrist-frame MPJPE %.2f mm "
      "(one view alone %.2f mm), wrist rotation error %.2f deg\n",
      mean_mm,
      mean_single_mm,
      mean_rot_deg);
  EXPECT_LT(mean_mm, 2.0);
  EXPECT_LT(mean_mm, mean_single_mm);
  EXPECT_LT(mean_rot_deg, 2.0);
}

TEST(FuseViewHands, IndependentOfViewOrder) {
  const HandModel model = HandModel::Default(HandSide::kRight);
  std::vector<Camera> cameras = testing::MakeRingRig(9, 2500, Eigen::Vector3d::Zero());
  std::mt19937 rng(8);
  HandPose truth = testing::RandomPose(model, rng, 0.1);
  truth.world_from_wrist.translation.setZero();
  std::vector<ViewHand3d> views = MakeViewHands(model, truth, cameras, rng);
  const FusedHand a = FuseViewHands(model, cameras, views, HandFusionOptions{});
  std::vector<int> order = {4, 8, 0, 2, 7, 1, 6, 3, 5};
  std::vector<Camera> cameras2;
  std::vector<ViewHand3d> views2;
  for (int i : order) cameras2.push_back(cameras[i]), views2.push_back(views[i]);
  const FusedHand b = FuseViewHands(model, cameras2, views2, HandFusionOptions{});
  ASSERT_TRUE(a.ok && b.ok);
  for (int d = 0; d < kNumJointDofs; ++d)
    EXPECT_NEAR(a.pose.angles_rad[d], b.pose.angles_rad[d], 1e-9);
  EXPECT_TRUE(a.pose.world_from_wrist.rotation.isApprox(b.pose.world_from_wrist.rotation, 1e-9));
  for (size_t i = 0; i < order.size(); ++i)
    EXPECT_NEAR(b.view_weights[i], a.view_weights[order[i]], 1e-12);
}

TEST(FuseViewHands, FaceOnViewsOutweighEdgeOnViews) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  HandPose pose;  // palm normal = world +z
  std::vector<Camera> cameras = testing::MakeRingRig(2, 2500, Eigen::Vector3d::Zero());
  // Camera 0 looks down the palm normal, camera 1 along the palm plane.
  auto look = [](Camera* c, const Eigen::Vector3d& center, const Eigen::Vector3d& up) {
    c->cam_from_world.rotation =
        arco::testing::CamFromWorldLookingAt(center, Eigen::Vector3d::Zero(), up);
    c->cam_from_world.translation = -c->cam_from_world.rotation * center;
  };
  look(&cameras[0], Eigen::Vector3d(0, 0, 2000), Eigen::Vector3d::UnitY());
  look(&cameras[1], Eigen::Vector3d(2000, 0, 0), Eigen::Vector3d::UnitY());
  std::vector<ViewHand3d> views(2);
  const HandPointsMm world = ForwardKinematics(model, pose);
  for (int v = 0; v < 2; ++v) {
    for (int k = 0; k < kNumHandKeypoints; ++k)
      views[v].points_in_camera_mm[k] = cameras[v].PointInCamera(world[k]);
  }
  const FusedHand fused = FuseViewHands(model, cameras, views, HandFusionOptions{});
  ASSERT_TRUE(fused.ok);
  EXPECT_GT(fused.view_weights[0], 5 * fused.view_weights[1]);
  EXPECT_LT(WristFrameMpjpe(model, fused.pose, pose), 0.1);
}

TEST(FuseViewHands, BadInputIsFlaggedNotFatal) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  const std::vector<Camera> cameras = testing::MakeRingRig(3, 2500, Eigen::Vector3d::Zero());
  std::vector<ViewHand3d> views(3);
  for (auto& v : views) v.points_in_camera_mm.fill(Eigen::Vector3d::Constant(std::nan("")));
  FusedHand r = FuseViewHands(model, cameras, views, HandFusionOptions{});
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(CountLimitViolations(model, r.pose), 0);
  for (auto& v : views) v.points_in_camera_mm.fill(Eigen::Vector3d(1, 2, 3));  // degenerate palm
  EXPECT_FALSE(FuseViewHands(model, cameras, views, HandFusionOptions{}).ok);
  views.pop_back();
  EXPECT_THROW(FuseViewHands(model, cameras, views, HandFusionOptions{}), std::invalid_argument);
  HandFusionOptions o;
  o.view_angle_floor = 0;
  EXPECT_FALSE(o.Validate().ok());
}

TEST(JointDecomposition, RoundTripsWithinTheLimits) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::mt19937 rng(2);
  for (int trial = 0; trial < 50; ++trial) {
    const HandPose pose = testing::RandomPose(model, rng);
    const auto local = LocalJointRotations(model, pose);
    for (int f = 0; f < kNumFingers; ++f) {
      const Finger finger = static_cast<Finger>(f);
      const int k0 = KeypointIndex(finger, 0);
      double flex, abd;
      DecomposeUniversalJoint(local[k0],
                              model.axis(DofIndex(finger, FingerDof::kBaseFlex)),
                              model.axis(DofIndex(finger, FingerDof::kBaseAbd)),
                              &flex,
                              &abd);
      EXPECT_NEAR(flex, pose.angle_rad(finger, FingerDof::kBaseFlex), 1e-12);
      EXPECT_NEAR(abd, pose.angle_rad(finger, FingerDof::kBaseAbd), 1e-12);
      EXPECT_NEAR(AngleAboutAxis(Eigen::Quaterniond(local[k0 + 1]),
                                 model.axis(DofIndex(finger, FingerDof::kMiddleFlex))),
                  pose.angle_rad(finger, FingerDof::kMiddleFlex),
                  1e-12);
      // q and -q are the same rotation.
      const Eigen::Quaterniond q(local[k0 + 2]);
      const Eigen::Quaterniond minus_q(-q.w(), -q.x(), -q.y(), -q.z());
      EXPECT_NEAR(AngleAboutAxis(minus_q, model.axis(DofIndex(finger, FingerDof::kDistalFlex))),
                  pose.angle_rad(finger, FingerDof::kDistalFlex),
                  1e-12);
    }
  }
}

}  // namespace
}  // namespace arco::hand
