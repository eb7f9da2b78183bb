#include "arco/hand/fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>

#include "arco/hand/hand_test_util.h"
#include "arco/hand/synthetic_rig.h"

namespace arco::hand {
namespace {

double Mpjpe(const HandModel& model, const HandPose& a, const HandPose& b) {
  const HandPointsMm pa = ForwardKinematics(model, a), pb = ForwardKinematics(model, b);
  double sum = 0;
  for (int k = 0; k < kNumHandKeypoints; ++k) sum += (pa[k] - pb[k]).norm();
  return sum / kNumHandKeypoints;
}

TEST(FitHandToPoints3d, RecoversExactAndNoisyPoints) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::mt19937 rng(1);
  std::normal_distribution<double> n(0.0, 1.0);
  double worst_exact = 0, mean_noisy = 0, mean_raw = 0;
  const int trials = 20;
  for (int trial = 0; trial < trials; ++trial) {
    const HandPose truth = testing::RandomPose(model, rng, 0.05);
    HandPointsMm points = ForwardKinematics(model, truth);
    const HandFit3dResult exact = FitHandToPoints3d(model, points, HandFit3dOptions{});
    ASSERT_TRUE(exact.ok) << exact.problem;
    worst_exact = std::max(worst_exact, Mpjpe(model, exact.pose, truth));
    for (auto& p : points) p += 2.0 * Eigen::Vector3d(n(rng), n(rng), n(rng));
    points[8] += Eigen::Vector3d(40, 0, 0);  // one gross outlier
    points[15].setConstant(std::nan(""));    // one missing
    const HandPointsMm clean = ForwardKinematics(model, truth);
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      if (points[k].allFinite()) mean_raw += (points[k] - clean[k]).norm() / (20.0 * trials);
    }
    const HandFit3dResult noisy = FitHandToPoints3d(model, points, HandFit3dOptions{});
    ASSERT_TRUE(noisy.ok);
    EXPECT_EQ(CountLimitViolations(model, noisy.pose, 0.0), 0);
    mean_noisy += Mpjpe(model, noisy.pose, truth) / trials;
  }
  std::printf(
      "[ fit3d ] exact points: worst MPJPE %.2e mm; 2 mm/axis noise + one 40 mm outlier: input "
      "error %.2f mm, fitted MPJPE %.2f mm\n",
      worst_exact,
      mean_raw,
      mean_noisy);
  EXPECT_LT(worst_exact, 0.05);
  EXPECT_LT(mean_noisy, 0.7 * mean_raw);
}

TEST(FitHandToPoints3d, FlagsTooFewOrCollinearPalmPoints) {
  const HandModel model = HandModel::Default(HandSide::kRight);
  HandPointsMm points;
  for (auto& p : points) p.setConstant(std::nan(""));
  EXPECT_FALSE(FitHandToPoints3d(model, points, HandFit3dOptions{}).ok);
  for (int k : {0, 5, 9}) points[k] = Eigen::Vector3d(k, 0, 0);  // collinear
  const HandFit3dResult r = FitHandToPoints3d(model, points, HandFit3dOptions{});
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(CountLimitViolations(model, r.pose), 0);
}

struct RigCase {
  int num_cameras;
  double noise_px;
  double outlier_fraction;
};

// Generated truth: random joint-limited poses -> FK -> synthetic rig with
// noise, outlier keypoints and one corrupted view -> multi-view fit.
TEST(FitHandMultiView, RecoversRandomPosesInSyntheticRigs) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::mt19937 rng(2024);
  for (const RigCase rc : {RigCase{8, 1.5, 0.05}, RigCase{20, 3.0, 0.10}}) {
    const std::vector<Camera> cameras =
        testing::MakeRingRig(rc.num_cameras, 2500, Eigen::Vector3d::Zero());
    const int trials = 15;
    double mean_mm = 0, worst_mm = 0, mean_px = 0;
    int bad_view_rejected = 0;
    for (int trial = 0; trial < trials; ++trial) {
      const HandPose truth = testing::RandomPose(model, rng, 0.05);
      std::vector<HandKeypoints2d> views = testing::ProjectHand(
          cameras, ForwardKinematics(model, truth), rc.noise_px, rc.outlier_fraction, rng);
      const int bad = trial % rc.num_cameras;  // a view that sees something else
      for (auto& p : views[bad].pixels) p += Eigen::Vector2d(90, -60);
      const HandFitResult r =
          FitHandMultiView(model, cameras, views, HandFitInit{}, HandFitOptions{});
      ASSERT_TRUE(r.ok) << r.problem;
      EXPECT_EQ(r.init_source, "triangulated");
      EXPECT_EQ(CountLimitViolations(model, r.pose, 0.0), 0);
      const double mm = Mpjpe(model, r.pose, truth);
      mean_mm += mm / trials;
      mean_px += r.median_residual_px / trials;
      worst_mm = std::max(worst_mm, mm);
      bad_view_rejected += !r.trusted_views[bad];
    }
    std::printf(
        "[ fit2d ] %d cameras, %.1f px noise, %.0f%% outliers, 1 bad view: MPJPE mean %.2f mm, "
        "worst %.2f mm, median residual %.2f px, bad view rejected %d/%d\n",
        rc.num_cameras,
        rc.noise_px,
        100 * rc.outlier_fraction,
        mean_mm,
        worst_mm,
        mean_px,
        bad_view_rejected,
        trials);
    EXPECT_LT(mean_mm, 2.0);
    EXPECT_LT(worst_mm, 5.0);
    EXPECT_EQ(bad_view_rejected, trials);
  }
}

TEST(FitHandMultiView, TracksASequenceFromThePreviousFrame) {
  const HandModel model = HandModel::Default(HandSide::kRight);
  const std::vector<Camera> cameras = testing::MakeRingRig(10, 1500, Eigen::Vector3d::Zero());
  std::mt19937 rng(77);
  HandPose truth = testing::RandomPose(model, rng, 0.2);
  HandFitInit init;
  init.previous_pose = truth;
  for (int frame = 0; frame < 10; ++frame) {
    for (double& a : truth.angles_rad) a += 0.02;
    truth = ClampToLimits(model, truth);
    truth.world_from_wrist.translation += Eigen::Vector3d(2, 0, -1);
    const auto views =
        testing::ProjectHand(cameras, ForwardKinematics(model, truth), 1.0, 0.0, rng);
    const HandFitResult r = FitHandMultiView(model, cameras, views, init, HandFitOptions{});
    ASSERT_TRUE(r.ok) << r.problem;
    EXPECT_EQ(r.init_source, "previous");
    EXPECT_LT(Mpjpe(model, r.pose, truth), 2.0) << "frame " << frame;
    init.previous_pose = r.pose;
  }
}

TEST(FitHandMultiView, FlagsFramesWithMissingKeypointsInMostViews) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  const std::vector<Camera> cameras = testing::MakeRingRig(12, 1500, Eigen::Vector3d::Zero());
  std::mt19937 rng(5);
  const HandPose truth = testing::RandomPose(model, rng, 0.1);
  std::vector<HandKeypoints2d> views =
      testing::ProjectHand(cameras, ForwardKinematics(model, truth), 1.0, 0.0, rng);
  for (size_t v = 1; v < views.size(); ++v) views[v].scores.fill(0.0);  // seen in one view only
  const HandFitResult r = FitHandMultiView(model, cameras, views, HandFitInit{}, HandFitOptions{});
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.problem.find("seen in 1 views"), std::string::npos) << r.problem;
  EXPECT_EQ(CountLimitViolations(model, r.pose), 0);
}

TEST(FitHandMultiView, SurvivesNanAndDegenerateInput) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  const std::vector<Camera> cameras = testing::MakeRingRig(8, 1500, Eigen::Vector3d::Zero());
  std::mt19937 rng(6);
  const HandPose truth = testing::RandomPose(model, rng, 0.1);
  std::vector<HandKeypoints2d> views =
      testing::ProjectHand(cameras, ForwardKinematics(model, truth), 1.0, 0.0, rng);
  // NaN pixels with high scores, NaN scores: ignored.
  views[0].pixels[3].setConstant(std::nan(""));
  views[1].scores[4] = std::nan("");
  HandFitResult r = FitHandMultiView(model, cameras, views, HandFitInit{}, HandFitOptions{});
  EXPECT_TRUE(r.ok) << r.problem;
  EXPECT_LT(Mpjpe(model, r.pose, truth), 2.0);
  // Every keypoint at the same pixel in every view: no crash, limits hold.
  for (auto& v : views) v.pixels.fill(Eigen::Vector2d(1000, 1000));
  r = FitHandMultiView(model, cameras, views, HandFitInit{}, HandFitOptions{});
  EXPECT_EQ(CountLimitViolations(model, r.pose), 0);
  // All NaN: flagged.
  for (auto& v : views) v.pixels.fill(Eigen::Vector2d::Constant(std::nan("")));
  r = FitHandMultiView(model, cameras, views, HandFitInit{}, HandFitOptions{});
  EXPECT_FALSE(r.ok);
  // A previous pose with NaN is not used as an initialisation.
  HandFitInit init;
  init.previous_pose = truth;
  init.previous_pose->world_from_wrist.translation.x() = std::nan("");
  r = FitHandMultiView(model, cameras, views, init, HandFitOptions{});
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(CountLimitViolations(model, r.pose), 0);
}

TEST(FitHandMultiView, RejectsCallerErrors) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  const std::vector<Camera> cameras = testing::MakeRingRig(4, 1500, Eigen::Vector3d::Zero());
  std::vector<HandKeypoints2d> views(3);
  EXPECT_THROW(FitHandMultiView(model, cameras, views, HandFitInit{}, HandFitOptions{}),
               std::invalid_argument);
  HandFitOptions o;
  o.robust_loss_px = 0;
  EXPECT_FALSE(o.Validate().ok());
  o = HandFitOptions{};
  o.min_score = 2;
  EXPECT_FALSE(o.Validate().ok());
  o = HandFitOptions{};
  o.temporal_angle_weight_px_per_rad = -1;
  EXPECT_FALSE(o.Validate().ok());
  views.resize(4);
  EXPECT_THROW(FitHandMultiView(model, cameras, views, HandFitInit{}, o), std::invalid_argument);
}

}  // namespace
}  // namespace arco::hand
