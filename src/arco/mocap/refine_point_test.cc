#include "arco/mocap/refine_point.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "arco/mocap/refine_point_pixels.h"
#include "arco/testing/synthetic_views.h"

namespace arco {
namespace {

std::vector<RefinementView> Observe(const Rig& rig,
                                    const Eigen::Vector3d& x,
                                    double noise_px,
                                    std::mt19937* rng) {
  std::normal_distribution<double> n(0, noise_px);
  std::uniform_real_distribution<double> w(0.5, 1.0);
  std::vector<RefinementView> views;
  for (const Camera& c : rig.cameras) {
    const auto pixel = c.Project(x);
    if (pixel) views.push_back({&c, *pixel + Eigen::Vector2d(n(*rng), n(*rng)), w(*rng)});
  }
  return views;
}

// The robust cost the solver minimises, written directly from the loss.
double RobustCost(const std::vector<RefinementView>& views, double b, const Eigen::Vector3d& x) {
  double cost = 0;
  for (const auto& v : views) {
    const double s = (v.sqrt_weight * (*v.camera->Project(x) - v.pixel)).squaredNorm();
    cost += 2 * b * b * (std::sqrt(1 + s / (b * b)) - 1);
  }
  return cost;
}

TEST(RefinePointRobust, ConvergesToTheTruthWithoutNoise) {
  testing::SyntheticRigOptions o;
  o.num_cameras = 8;
  const Rig rig = testing::MakeSyntheticRig(o);
  std::mt19937 rng(1);
  const Eigen::Vector3d truth(0.2, -0.1, 1.3);
  const auto views = Observe(rig, truth, 0.0, &rng);
  PointRefinementOptions tight;
  tight.function_tolerance_px2 = 1e-20;
  tight.parameter_tolerance = 1e-14;
  for (const auto& options : {PointRefinementOptions(), tight}) {
    Eigen::Vector3d x = truth + Eigen::Vector3d(0.03, -0.02, 0.04);
    const auto summary = RefinePointRobust(views.data(), views.size(), options, &x);
    EXPECT_LT(summary.final_cost, summary.initial_cost);
    EXPECT_GT(summary.evaluations, 1);
    // Default tolerances stop within micrometres; tight ones at rounding level.
    EXPECT_LT((x - truth).norm(), options.function_tolerance_px2 > 1e-10 ? 1e-5 : 1e-10);
  }
}

TEST(RefinePointRobust, EndsAtAMinimumOfTheRobustCost) {
  testing::SyntheticRigOptions o;
  o.num_cameras = 12;
  const Rig rig = testing::MakeSyntheticRig(o);
  std::mt19937 rng(2);
  const double b = 3.0;
  for (int i = 0; i < 10; ++i) {
    const Eigen::Vector3d truth(0.3 * std::sin(i), 0.3 * std::cos(i), 0.8 + 0.05 * i);
    auto views = Observe(rig, truth, 1.0, &rng);
    views[i % views.size()].pixel += Eigen::Vector2d(12, -5);  // inside a 15 px gate
    PointRefinementOptions options;
    options.loss_scale_px = b;
    options.function_tolerance_px2 = 1e-14;
    Eigen::Vector3d x = truth + Eigen::Vector3d(0.01, 0.01, -0.01);
    const auto summary = RefinePointRobust(views.data(), views.size(), options, &x);
    EXPECT_NEAR(summary.final_cost, RobustCost(views, b, x), 1e-9 * summary.final_cost);
    // Central differences of the cost vanish at the minimum (1 um steps) ...
    const double h = 1e-6;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d e = h * Eigen::Vector3d::Unit(k);
      const double slope = (RobustCost(views, b, x + e) - RobustCost(views, b, x - e)) / (2 * h);
      EXPECT_LT(std::abs(slope), 1e-2) << "point " << i << " axis " << k;  // px^2 per m
    }
    // ... and no nearby point is lower.
    std::uniform_real_distribution<double> d(-1e-4, 1e-4);
    for (int t = 0; t < 20; ++t) {
      const Eigen::Vector3d y = x + Eigen::Vector3d(d(rng), d(rng), d(rng));
      EXPECT_GE(RobustCost(views, b, y), summary.final_cost - 1e-9);
    }
  }
}

// The pixels handed back are Camera::Project's at the returned point, bit for bit, and
// the point and summary are RefinePointRobust's (the triangulation's final classification
// uses them instead of projecting again).
TEST(RefinePointRobustWithPixels, PixelsAreTheProjectionsAtTheReturnedPoint) {
  testing::SyntheticRigOptions o;
  o.num_cameras = 12;
  const Rig rig = testing::MakeSyntheticRig(o);
  std::mt19937 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d truth(0.1 * trial - 1.0, 0.05 * trial - 0.5, 1.2);
    const auto views = Observe(rig, truth, 2.0, &rng);
    const int count = static_cast<int>(views.size());
    const Eigen::Vector3d start = truth + Eigen::Vector3d(0.02, -0.03, 0.05);
    Eigen::Vector3d x = start, y = start;
    const auto expected = RefinePointRobust(views.data(), count, PointRefinementOptions(), &x);
    std::vector<Eigen::Vector2d> pixels(2 * static_cast<size_t>(count));
    PointRefinementSummary summary;
    ASSERT_TRUE(internal::RefinePointRobustWithPixels(
        views.data(), count, PointRefinementOptions(), &y, pixels.data(), &summary));
    EXPECT_EQ(x, y);
    EXPECT_EQ(summary.final_cost, expected.final_cost);
    EXPECT_EQ(summary.evaluations, expected.evaluations);
    for (int i = 0; i < count; ++i) EXPECT_EQ(pixels[i], *views[i].camera->Project(y)) << i;
  }
}

TEST(RefinePointRobust, StartBehindACameraIsLeftAlone) {
  const Rig rig = testing::MakeSyntheticRig(testing::SyntheticRigOptions());
  std::mt19937 rng(3);
  const auto views = Observe(rig, Eigen::Vector3d(0, 0, 1), 0.5, &rng);
  // 10 m from the origin the point is behind the cameras on the other side of the ring.
  const Eigen::Vector3d start(10, 0, 1);
  Eigen::Vector3d x = start;
  const auto summary = RefinePointRobust(views.data(), views.size(), PointRefinementOptions(), &x);
  EXPECT_EQ(x, start);
  EXPECT_TRUE(std::isinf(summary.initial_cost));
  EXPECT_EQ(summary.iterations, 0);
}

TEST(PointRefinementOptions, ValidateRejectsBadValues) {
  EXPECT_TRUE(PointRefinementOptions().Validate().ok());
  PointRefinementOptions o;
  o.loss_scale_px = 0;
  EXPECT_FALSE(o.Validate().ok());
  o = PointRefinementOptions();
  o.max_iterations = 0;
  EXPECT_FALSE(o.Validate().ok());
  o = PointRefinementOptions();
  o.function_tolerance_px2 = -1;
  EXPECT_FALSE(o.Validate().ok());
}

}  // namespace
}  // namespace arco
