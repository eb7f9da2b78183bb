// SolveRigidPose on synthetic correspondences: exact ones give the pose back, gross
// outliers are rejected by RANSAC, noise leaves a sub-millimetre error, and bad input
// is refused.
#include "arco/track/pose_solver.h"

#include <gtest/gtest.h>

#include <random>

#include "arco/testing/look_at.h"

namespace arco::track {
namespace {

std::vector<Camera> Rig3() {
  std::vector<Camera> cams;
  for (int i = 0; i < 3; ++i) {
    Camera c;
    c.name = "cam" + std::to_string(i);
    c.width = 1000;
    c.height = 800;
    c.fx = c.fy = 1000;
    c.cx = 500;
    c.cy = 400;
    c.distortion.k1 = -0.05 * (i + 1);
    c.distortion.p1 = 0.001;
    // Cameras on an arc at 2.5 m looking at the origin.
    const double a = (i - 1) * 0.6;
    const Eigen::Vector3d centre(2500 * std::sin(a), -2500 * std::cos(a), 100.0 * i);
    const Eigen::Matrix3d R = testing::CamFromWorldLookingAt(centre, Eigen::Vector3d::Zero());
    c.cam_from_world.rotation = R;
    c.cam_from_world.translation = -R * centre;
    cams.push_back(c);
  }
  return cams;
}

Rigid3d TruePose() {
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.2, Eigen::Vector3d(0.3, -1, 0.5).normalized()));
  return Rigid3d(q, Eigen::Vector3d(40, -25, 60));
}

std::vector<PoseCorrespondence> Make(const std::vector<Camera>& cams,
                                     const Rigid3d& pose,
                                     int per_view,
                                     double noise_px,
                                     double outlier_fraction,
                                     uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-400, 400);
  std::normal_distribution<double> noise(0, noise_px);
  std::uniform_real_distribution<double> flip(0, 1);
  std::vector<PoseCorrespondence> out;
  for (int v = 0; v < static_cast<int>(cams.size()); ++v) {
    for (int k = 0; k < per_view; ++k) {
      const Eigen::Vector3d x(u(rng), u(rng) * 0.2, u(rng) * 1.5);
      Eigen::Vector2d px = *cams[v].Project(pose * x);
      if (flip(rng) < outlier_fraction) {
        px += Eigen::Vector2d(u(rng) * 0.2, u(rng) * 0.2);  // up to 80 px off
      } else {
        px += Eigen::Vector2d(noise(rng), noise(rng));
      }
      out.push_back({v, x, px, 1.0});
    }
  }
  return out;
}

double RotationErrorDeg(const Rigid3d& a, const Rigid3d& b) {
  return a.rotation.angularDistance(b.rotation) * 180 / M_PI;
}

TEST(PoseSolver, ExactCorrespondencesGiveThePoseBack) {
  const auto cams = Rig3();
  const auto c = Make(cams, TruePose(), 30, 0, 0, 1);
  const auto s = SolveRigidPose(cams, c, Rigid3d(), PoseSolverOptions());
  ASSERT_TRUE(s.has_value());
  EXPECT_LT((s->world_from_template.translation - TruePose().translation).norm(), 1e-3);
  EXPECT_LT(RotationErrorDeg(s->world_from_template, TruePose()), 1e-4);
  EXPECT_EQ(s->num_inliers, 90);
  EXPECT_LT(s->rms_px, 1e-3);
}

TEST(PoseSolver, RejectsFortyPercentOutliersFromAFarPrediction) {
  const auto cams = Rig3();
  const auto c = Make(cams, TruePose(), 60, 0.5, 0.4, 2);
  // The prediction is 10 degrees and 50 mm off.
  const Rigid3d prediction(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.17, Eigen::Vector3d::UnitZ())) * TruePose().rotation,
      TruePose().translation + Eigen::Vector3d(30, 30, -30));
  const auto s = SolveRigidPose(cams, c, prediction, PoseSolverOptions());
  ASSERT_TRUE(s.has_value());
  EXPECT_LT((s->world_from_template.translation - TruePose().translation).norm(), 2.0);
  EXPECT_LT(RotationErrorDeg(s->world_from_template, TruePose()), 0.2);
  // The outliers (about 72 of 180) are out, the noisy inliers in.
  EXPECT_GT(s->num_inliers, 90);
  EXPECT_LT(s->num_inliers, 125);
  EXPECT_LT(s->rms_px, 1.0);
  EXPECT_GE(s->trials, 2);
  EXPECT_LE(s->final_cost, s->initial_cost);
}

TEST(PoseSolver, SameAnswerEveryTime) {
  const auto cams = Rig3();
  const auto c = Make(cams, TruePose(), 40, 1.0, 0.3, 3);
  const auto a = SolveRigidPose(cams, c, Rigid3d(), PoseSolverOptions());
  const auto b = SolveRigidPose(cams, c, Rigid3d(), PoseSolverOptions());
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->world_from_template.translation, b->world_from_template.translation);
  EXPECT_EQ(a->inlier, b->inlier);
}

TEST(PoseSolver, TooFewOrBadInput) {
  const auto cams = Rig3();
  auto c = Make(cams, TruePose(), 1, 0, 0, 4);  // 3 correspondences < 6 inliers
  EXPECT_FALSE(SolveRigidPose(cams, c, TruePose(), PoseSolverOptions()).has_value());
  c[0].camera = 7;
  EXPECT_THROW(SolveRigidPose(cams, c, TruePose(), PoseSolverOptions()), std::invalid_argument);
  PoseSolverOptions bad;
  bad.inlier_px = 0;
  EXPECT_FALSE(bad.Validate().ok());
  bad = PoseSolverOptions();
  bad.sample_size = 2;
  EXPECT_FALSE(bad.Validate().ok());
}

}  // namespace
}  // namespace arco::track
