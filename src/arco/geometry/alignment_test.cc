// AlignPoints on generated point sets with a known transform: exact recovery,
// noise, weights, robust losses against gross outliers, degenerate inputs.
#include "arco/geometry/alignment.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "arco/geometry/rotation.h"

namespace arco {
namespace {

struct Problem {
  std::vector<Eigen::Vector3d> source, target;
  Sim3d truth;
};

Problem MakeProblem(int n, double scale, double noise, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-100, 100);  // e.g. mm
  std::normal_distribution<double> gauss(0, 1);
  Problem p;
  p.truth = Sim3d(scale,
                  QuaternionFromAxisAngle(Eigen::Vector3d(0.5, -1.2, 0.8)),
                  Eigen::Vector3d(300, -50, 1200));
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d s(u(rng), u(rng), u(rng));
    p.source.push_back(s);
    p.target.push_back(p.truth * s + noise * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)));
  }
  return p;
}

double TransformError(const Sim3d& a, const Sim3d& b, const std::vector<Eigen::Vector3d>& points) {
  double worst = 0;
  for (const auto& p : points) worst = std::max(worst, (a * p - b * p).norm());
  return worst;
}

TEST(AlignPoints, RecoversExactRigidAndSimilarityTransforms) {
  for (bool with_scale : {false, true}) {
    const Problem p = MakeProblem(20, with_scale ? 1.7 : 1.0, 0.0, 1);
    AlignmentOptions options;
    options.estimate_scale = with_scale;
    auto r = AlignPoints(p.source, p.target, {}, options);
    ASSERT_TRUE(r.has_value());
    EXPECT_LT(TransformError(r->target_from_source, p.truth, p.source), 1e-9);
    EXPECT_NEAR(r->target_from_source.scale, p.truth.scale, 1e-12);
    EXPECT_LT(r->rms_error, 1e-9);
    EXPECT_EQ(r->iterations, 0);
  }
}

TEST(AlignPoints, RigidFitOfScaledDataKeepsUnitScale) {
  const Problem p = MakeProblem(20, 1.3, 0.0, 2);
  auto r = AlignPoints(p.source, p.target, {}, AlignmentOptions{});
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->target_from_source.scale, 1.0);
  EXPECT_LT(RotationAngleBetween(r->target_from_source.rotation, p.truth.rotation), 1e-9);
  EXPECT_GT(r->rms_error, 1.0);  // the scale mismatch cannot be absorbed
}

TEST(AlignPoints, NoiseGivesSmallErrorAndRmsNearNoiseLevel) {
  const Problem p = MakeProblem(500, 1.0, 0.5, 3);
  auto r = AlignPoints(p.source, p.target, {}, AlignmentOptions{});
  ASSERT_TRUE(r.has_value());
  EXPECT_LT(TransformError(r->target_from_source, p.truth, p.source), 0.3);
  // E|noise| for 3D N(0, 0.5^2) is 0.5 * sqrt(3) ~ 0.87 (minus 6 fitted dof).
  EXPECT_NEAR(r->rms_error, 0.5 * std::sqrt(3.0), 0.08);
}

TEST(AlignPoints, ZeroWeightsAndNonFinitePointsAreIgnored) {
  Problem p = MakeProblem(12, 1.0, 0.0, 4);
  std::vector<double> weights(12, 1.0);
  p.target[3] += Eigen::Vector3d(500, 0, 0);
  weights[3] = 0;
  p.target[7] = Eigen::Vector3d(std::nan(""), 0, 0);
  p.source[9] = Eigen::Vector3d(0, INFINITY, 0);
  auto r = AlignPoints(p.source, p.target, weights, AlignmentOptions{});
  ASSERT_TRUE(r.has_value());
  EXPECT_LT(TransformError(r->target_from_source, p.truth, {p.source[0], p.source[1]}), 1e-9);
  EXPECT_TRUE(std::isnan(r->residuals[3]));
  EXPECT_TRUE(std::isnan(r->residuals[7]));
  EXPECT_EQ(r->robust_weights[9], 0.0);
}

TEST(AlignPoints, WeightsFavourTrustedPoints) {
  // Half the points are shifted; trusting the other half recovers the truth better.
  Problem p = MakeProblem(40, 1.0, 0.0, 5);
  for (int i = 0; i < 20; ++i) p.target[i] += Eigen::Vector3d(0, 0, 5);
  std::vector<double> trust(40, 1.0);
  for (int i = 0; i < 20; ++i) trust[i] = 0.01;
  auto equal = AlignPoints(p.source, p.target, {}, AlignmentOptions{});
  auto weighted = AlignPoints(p.source, p.target, trust, AlignmentOptions{});
  const std::vector<Eigen::Vector3d> clean(p.source.begin() + 20, p.source.end());
  EXPECT_LT(TransformError(weighted->target_from_source, p.truth, clean),
            0.1 * TransformError(equal->target_from_source, p.truth, clean));
}

TEST(AlignPoints, RobustLossesRejectGrossOutliers) {
  Problem p = MakeProblem(100, 1.4, 0.2, 6);
  std::mt19937 rng(60);
  std::uniform_real_distribution<double> u(-400, 400);
  for (int i = 0; i < 100; i += 4) p.target[i] = Eigen::Vector3d(u(rng), u(rng), u(rng));  // 25%
  std::vector<Eigen::Vector3d> inliers;
  for (int i = 0; i < 100; ++i) {
    if (i % 4) inliers.push_back(p.source[i]);
  }
  AlignmentOptions plain;
  plain.estimate_scale = true;
  auto ls = AlignPoints(p.source, p.target, {}, plain);
  ASSERT_TRUE(ls.has_value());
  const double ls_error = TransformError(ls->target_from_source, p.truth, inliers);
  EXPECT_GT(ls_error, 20.0);  // least squares is dragged away
  for (RobustLoss loss : {RobustLoss::kHuber, RobustLoss::kCauchy}) {
    AlignmentOptions robust = plain;
    robust.loss = loss;
    robust.loss_scale = 1.0;
    robust.max_iterations = 200;
    auto r = AlignPoints(p.source, p.target, {}, robust);
    ASSERT_TRUE(r.has_value());
    EXPECT_TRUE(r->converged);
    EXPECT_GT(r->iterations, 1);
    const double error = TransformError(r->target_from_source, p.truth, inliers);
    EXPECT_LT(error, loss == RobustLoss::kCauchy ? 0.5 : 2.0) << static_cast<int>(loss);
    for (int i = 0; i < 100; i += 4) EXPECT_LT(r->robust_weights[i], 0.1);
  }
}

TEST(AlignPoints, ResultDoesNotDependOnPointOrder) {
  Problem p = MakeProblem(30, 1.2, 0.3, 7);
  AlignmentOptions options;
  options.estimate_scale = true;
  options.loss = RobustLoss::kCauchy;
  auto a = AlignPoints(p.source, p.target, {}, options);
  std::vector<int> order(30);
  for (int i = 0; i < 30; ++i) order[i] = (i * 7) % 30;
  std::vector<Eigen::Vector3d> s, t;
  for (int i : order) {
    s.push_back(p.source[i]);
    t.push_back(p.target[i]);
  }
  auto b = AlignPoints(s, t, {}, options);
  EXPECT_LT(TransformError(a->target_from_source, b->target_from_source, p.source), 1e-8);
}

TEST(AlignPoints, MirroredTargetStillGivesAProperRotation) {
  Problem p = MakeProblem(10, 1.0, 0.0, 8);
  for (auto& t : p.target) t.x() = -t.x();
  auto r = AlignPoints(p.source, p.target, {}, AlignmentOptions{});
  ASSERT_TRUE(r.has_value());
  EXPECT_NEAR(r->target_from_source.RotationMatrix().determinant(), 1.0, 1e-12);
}

TEST(AlignPoints, DegenerateInputsGiveNullopt) {
  const Problem p = MakeProblem(10, 1.0, 0.0, 9);
  AlignmentOptions options;
  EXPECT_FALSE(AlignPoints({p.source[0], p.source[1]}, {p.target[0], p.target[1]}, {}, options));
  std::vector<Eigen::Vector3d> line, line_target;
  for (int i = 0; i < 5; ++i) {
    line.push_back(Eigen::Vector3d(i, 2 * i, -i));
    line_target.push_back(p.truth * line.back());
  }
  EXPECT_FALSE(AlignPoints(line, line_target, {}, options).has_value());
  std::vector<Eigen::Vector3d> same(5, Eigen::Vector3d(1, 2, 3));
  EXPECT_FALSE(AlignPoints(same, same, {}, options).has_value());
  EXPECT_FALSE(AlignPoints(p.source, p.target, std::vector<double>(10, 0.0), options).has_value());
  EXPECT_FALSE(AlignPoints({}, {}, {}, options).has_value());
}

TEST(AlignPoints, InvalidArgumentsThrow) {
  const Problem p = MakeProblem(5, 1.0, 0.0, 10);
  AlignmentOptions options;
  EXPECT_THROW(AlignPoints(p.source, {p.target[0]}, {}, options), std::invalid_argument);
  EXPECT_THROW(AlignPoints(p.source, p.target, {1.0}, options), std::invalid_argument);
  EXPECT_THROW(AlignPoints(p.source, p.target, {1, 1, -1, 1, 1}, options), std::invalid_argument);
  options.loss_scale = 0;
  EXPECT_THROW(options.Validate(), std::invalid_argument);
  options = AlignmentOptions{};
  options.max_iterations = 0;
  EXPECT_THROW(AlignPoints(p.source, p.target, {}, options), std::invalid_argument);
}

}  // namespace
}  // namespace arco
