#include "arco/geometry/triangulation.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <random>

#include "arco/testing/look_at.h"

namespace arco {
namespace {

// A ring of cameras looking at the origin from `radius` (world units).
std::vector<Matrix34d> RingCameras(int n, double radius) {
  std::vector<Matrix34d> cams;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    const Eigen::Vector3d center(radius * std::cos(a), radius * std::sin(a), 0.3 * radius);
    const Eigen::Matrix3d r = testing::CamFromWorldLookingAt(center, Eigen::Vector3d::Zero());
    Matrix34d p;
    p.leftCols<3>() = r;
    p.col(3) = -r * center;
    cams.push_back(p);
  }
  return cams;
}

std::vector<DltObservation> Observe(const std::vector<Matrix34d>& cams,
                                    const Eigen::Vector3d& x,
                                    double noise,
                                    std::mt19937* rng) {
  std::normal_distribution<double> n(0, noise);
  std::vector<DltObservation> obs;
  for (const auto& p : cams) {
    DltObservation o;
    o.projection = p;
    o.point = (p * x.homogeneous()).hnormalized() + Eigen::Vector2d(n(*rng), n(*rng));
    obs.push_back(o);
  }
  return obs;
}

WorldConditioning ConditioningOf(const std::vector<Matrix34d>& cams) {
  std::vector<Eigen::Vector3d> centers;
  for (const auto& p : cams) centers.push_back(-p.leftCols<3>().transpose() * p.col(3));
  return ConditioningFromCameraCenters(centers);
}

TEST(TriangulateDlt, ExactOnNoiseFreeViewsAtAnyScale) {
  std::mt19937 rng(3);
  for (double scale : {1e-3, 1.0, 2000.0}) {
    const auto cams = RingCameras(6, 3.0 * scale);
    const Eigen::Vector3d truth = Eigen::Vector3d(0.1, -0.2, 0.15) * scale;
    const auto x = TriangulateDlt(Observe(cams, truth, 0.0, &rng), ConditioningOf(cams));
    ASSERT_TRUE(x.has_value());
    EXPECT_LT((*x - truth).norm(), 1e-9 * scale) << "scale " << scale;
  }
}

TEST(TriangulateDlt, NoisyViewsLandNearTruth) {
  std::mt19937 rng(4);
  const auto cams = RingCameras(8, 3.0);
  const Eigen::Vector3d truth(0.2, 0.1, -0.1);
  // 1e-3 normalised units is about 2 px at f = 2000 px.
  const auto x = TriangulateDlt(Observe(cams, truth, 1e-3, &rng), ConditioningOf(cams));
  ASSERT_TRUE(x.has_value());
  EXPECT_LT((*x - truth).norm(), 5e-3);
}

TEST(TriangulateDlt, ZeroWeightIgnoresAView) {
  std::mt19937 rng(5);
  const auto cams = RingCameras(4, 3.0);
  const Eigen::Vector3d truth(0.0, 0.1, 0.2);
  auto obs = Observe(cams, truth, 0.0, &rng);
  obs[2].point += Eigen::Vector2d(0.3, -0.2);  // a gross outlier...
  obs[2].weight = 0.0;                         // ...that carries no weight
  const auto x = TriangulateDlt(obs, ConditioningOf(cams));
  ASSERT_TRUE(x.has_value());
  EXPECT_LT((*x - truth).norm(), 1e-9);
}

TEST(TriangulateDlt, HigherWeightPullsTowardsTrustedViews) {
  std::mt19937 rng(6);
  const auto cams = RingCameras(5, 3.0);
  const Eigen::Vector3d truth(0.1, 0.1, 0.1);
  auto obs = Observe(cams, truth, 0.0, &rng);
  obs[0].point += Eigen::Vector2d(0.02, 0.0);
  const auto equal = TriangulateDlt(obs, ConditioningOf(cams));
  obs[0].weight = 0.05;
  const auto weighted = TriangulateDlt(obs, ConditioningOf(cams));
  ASSERT_TRUE(equal && weighted);
  EXPECT_LT((*weighted - truth).norm(), 0.5 * (*equal - truth).norm());
}

TEST(TriangulateDlt, FewerThanTwoWeightedViewsIsEmpty) {
  std::mt19937 rng(7);
  const auto cams = RingCameras(3, 3.0);
  auto obs = Observe(cams, Eigen::Vector3d::Zero(), 0.0, &rng);
  obs[0].weight = 0;
  obs[1].weight = 0;
  EXPECT_FALSE(TriangulateDlt(obs, ConditioningOf(cams)).has_value());
  obs.resize(1);
  obs[0].weight = 1;
  EXPECT_FALSE(TriangulateDlt(obs, ConditioningOf(cams)).has_value());
}

TEST(TriangulateDlt, InhomogeneousSolveMatchesTheEigenvectorOne) {
  std::mt19937 rng(9);
  DltOptions inhomogeneous;
  inhomogeneous.inhomogeneous = true;
  const auto cams = RingCameras(8, 3.0);
  const auto cond = ConditioningOf(cams);
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d truth(0.3 * std::sin(i), 0.3 * std::cos(i), 0.02 * i - 0.2);
    // Exact without noise, like the eigenvector solve.
    const auto exact = TriangulateDlt(Observe(cams, truth, 0.0, &rng), cond, inhomogeneous);
    ASSERT_TRUE(exact.has_value());
    EXPECT_LT((*exact - truth).norm(), 1e-9);
    // With noise (about 2 px) the two minimisers differ far below the 3D error itself.
    const auto obs = Observe(cams, truth, 1e-3, &rng);
    const auto a = TriangulateDlt(obs, cond);
    const auto b = TriangulateDlt(obs, cond, inhomogeneous);
    ASSERT_TRUE(a.has_value() && b.has_value());
    EXPECT_LT((*a - *b).norm(), 1e-2 * (*a - truth).norm() + 1e-9);
  }
  // Two views of the same camera: the normal equations are singular.
  auto obs = Observe(cams, Eigen::Vector3d(0.1, 0.2, 0.3), 0.0, &rng);
  obs[1] = obs[0];
  obs.resize(2);
  EXPECT_FALSE(TriangulateDlt(obs, cond, inhomogeneous).has_value());
}

TEST(SolveSymmetric3x3, MatchesCholeskyAndRefusesSingularSystems) {
  std::mt19937 rng(10);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 100; ++i) {
    Eigen::Matrix3d m;
    for (int k = 0; k < 9; ++k) m.data()[k] = u(rng);
    const double scale = std::pow(10.0, 6 * u(rng));  // any scale
    const Eigen::Matrix3d a = scale * (m * m.transpose() + 0.1 * Eigen::Matrix3d::Identity());
    const Eigen::Vector3d b(u(rng), u(rng), u(rng));
    const auto x = SolveSymmetric3x3(a, b);
    ASSERT_TRUE(x.has_value());
    const Eigen::Vector3d expected = a.llt().solve(b);
    EXPECT_LT((*x - expected).norm(), 1e-9 * expected.norm());
  }
  // Rank 2 (two equal rows and columns), zero, and negative definite.
  Eigen::Matrix3d rank2;
  rank2 << 2, 1, 1, 1, 3, 3, 1, 3, 3;
  EXPECT_FALSE(SolveSymmetric3x3(rank2, Eigen::Vector3d(1, 2, 3)).has_value());
  EXPECT_FALSE(SolveSymmetric3x3(Eigen::Matrix3d::Zero(), Eigen::Vector3d(1, 2, 3)).has_value());
  EXPECT_FALSE(
      SolveSymmetric3x3(-Eigen::Matrix3d::Identity(), Eigen::Vector3d(1, 2, 3)).has_value());
}

TEST(TriangulateTwoViews, MatchesDltOnTwoViewsAndRejectsParallelRays) {
  std::mt19937 rng(8);
  const auto cams = RingCameras(4, 3.0);
  const Eigen::Vector3d truth(0.3, -0.1, 0.05);
  const auto obs = Observe(cams, truth, 0.0, &rng);
  const auto x = TriangulateTwoViewsConditioned(cams[0], obs[0].point, cams[1], obs[1].point);
  ASSERT_TRUE(x.has_value());
  EXPECT_LT((*x - truth).norm(), 1e-9);
  // The same camera twice: the rays coincide, depth is undetermined.
  EXPECT_FALSE(
      TriangulateTwoViewsConditioned(cams[0], obs[0].point, cams[0], obs[0].point).has_value());
}

TEST(ConditionProjection, ConditionedSolutionMapsBack) {
  const auto cams = RingCameras(2, 5.0);
  WorldConditioning c;
  c.center = Eigen::Vector3d(1, 2, 3);
  c.scale = 7.0;
  const Eigen::Vector3d xw(0.5, -0.25, 2.0);
  const Eigen::Vector3d xc = (xw - c.center) / c.scale;
  const Matrix34d pc = ConditionProjection(cams[0], c);
  EXPECT_TRUE((pc * xc.homogeneous())
                  .hnormalized()
                  .isApprox((cams[0] * xw.homogeneous()).hnormalized(), 1e-12));
}

}  // namespace
}  // namespace arco
