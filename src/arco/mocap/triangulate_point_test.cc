#include "arco/mocap/triangulate_point.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <stdexcept>

#include "arco/testing/synthetic_views.h"

namespace arco {
namespace {

std::vector<PointObservation> Observe(const Rig& rig,
                                      const Eigen::Vector3d& x,
                                      double noise_px,
                                      std::mt19937* rng) {
  std::normal_distribution<double> n(0, noise_px);
  std::vector<PointObservation> obs;
  for (int c = 0; c < static_cast<int>(rig.cameras.size()); ++c) {
    const auto pixel = rig.cameras[c].Project(x);
    if (!pixel) continue;
    obs.push_back({c, *pixel + Eigen::Vector2d(n(*rng), n(*rng)), 0.9});
  }
  return obs;
}

Rig SmallRig(int n, bool distortion = true) {
  testing::SyntheticRigOptions o;
  o.num_cameras = n;
  o.distortion = distortion;
  return testing::MakeSyntheticRig(o);
}

TEST(TriangulateRobust, ExactWithoutNoiseThroughDistortion) {
  const Rig rig = SmallRig(6);
  std::mt19937 rng(1);
  const Eigen::Vector3d truth(0.2, -0.1, 1.3);
  const auto r = TriangulateRobust(rig, TriangulationOptions(), Observe(rig, truth, 0.0, &rng));
  ASSERT_TRUE(r.has_value());
  EXPECT_LT((r->point_in_world - truth).norm(), 1e-7);
  EXPECT_EQ(r->inlier_cameras.size(), 6u);
  EXPECT_EQ(r->num_views, 6);
  EXPECT_LT(r->rms_reprojection_px, 1e-5);
}

TEST(TriangulateRobust, NoiseGivesMatchingRmsAndSmallError) {
  const Rig rig = SmallRig(12);
  std::mt19937 rng(2);
  double sum_rms = 0;
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector3d truth(0.3 * std::sin(i), 0.3 * std::cos(i), 0.5 + 0.02 * i);
    const auto r = TriangulateRobust(rig, TriangulationOptions(), Observe(rig, truth, 1.0, &rng));
    ASSERT_TRUE(r.has_value());
    // 1 px at f = 2260 and 3 m is about 1.3 mm per view; many views average it down.
    EXPECT_LT((r->point_in_world - truth).norm(), 2e-3);
    sum_rms += r->rms_reprojection_px;
  }
  // The RMS of 2D residuals for sigma = 1 px per axis is about sqrt(2 (1 - 3/(2n))) px.
  EXPECT_NEAR(sum_rms / 50, std::sqrt(2.0 * (1 - 3.0 / 24)), 0.15);
}

TEST(TriangulateRobust, RejectsOutlierViews) {
  const Rig rig = SmallRig(10);
  std::mt19937 rng(3);
  const Eigen::Vector3d truth(-0.1, 0.2, 1.1);
  auto obs = Observe(rig, truth, 0.5, &rng);
  obs[1].pixel += Eigen::Vector2d(120, -40);
  obs[4].pixel += Eigen::Vector2d(-300, 10);
  obs[7].pixel += Eigen::Vector2d(25, 25);
  obs[4].score = 1.0;  // the worst outlier is also the most confident detection
  const auto r = TriangulateRobust(rig, TriangulationOptions(), obs);
  ASSERT_TRUE(r.has_value());
  EXPECT_LT((r->point_in_world - truth).norm(), 1.5e-3);
  const std::vector<int> expected = {0, 2, 3, 5, 6, 8, 9};
  EXPECT_EQ(r->inlier_cameras, expected);
  EXPECT_EQ(r->num_views, 10);
}

TEST(TriangulateRobust, WithoutRansacAnOutlierWouldPullThePoint) {
  // Control for the test above: the same outliers in a plain DLT move the point.
  const Rig rig = SmallRig(10);
  std::mt19937 rng(3);
  const Eigen::Vector3d truth(-0.1, 0.2, 1.1);
  auto obs = Observe(rig, truth, 0.5, &rng);
  obs[4].pixel += Eigen::Vector2d(-300, 10);
  TriangulationOptions loose;
  loose.max_reprojection_px = 1e4;  // every view is an inlier
  loose.refine = false;
  const auto r = TriangulateRobust(rig, loose, obs);
  ASSERT_TRUE(r.has_value());
  EXPECT_GT((r->point_in_world - truth).norm(), 1e-2);
}

TEST(TriangulateRobust, OcclusionsAndLowScoresAreSkipped) {
  const Rig rig = SmallRig(8);
  std::mt19937 rng(4);
  const Eigen::Vector3d truth(0.0, 0.0, 1.0);
  auto obs = Observe(rig, truth, 0.3, &rng);
  obs[0].pixel = Eigen::Vector2d(NAN, NAN);
  obs[1].score = 0.1;
  obs[1].pixel += Eigen::Vector2d(500, 500);  // ignored because of its low score
  const auto r = TriangulateRobust(rig, TriangulationOptions(), obs);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->num_views, 6);
  EXPECT_EQ(r->inlier_cameras.size(), 6u);
  EXPECT_LT((r->point_in_world - truth).norm(), 1e-3);
}

TEST(TriangulateRobust, FewerThanTwoViewsOrDisagreementIsEmpty) {
  const Rig rig = SmallRig(4);
  std::mt19937 rng(5);
  const Eigen::Vector3d truth(0.1, 0.1, 1.0);
  auto obs = Observe(rig, truth, 0.0, &rng);
  EXPECT_FALSE(TriangulateRobust(rig, TriangulationOptions(), {obs[0]}).has_value());
  EXPECT_FALSE(TriangulateRobust(rig, TriangulationOptions(), {}).has_value());
  // Two views that do not agree (epipolar distance far beyond the gate).
  auto bad = obs;
  bad.resize(2);
  bad[1].pixel += Eigen::Vector2d(0, 300);
  bad[0].pixel += Eigen::Vector2d(0, -300);
  EXPECT_FALSE(TriangulateRobust(rig, TriangulationOptions(), bad).has_value());
}

TEST(TriangulateRobust, CheiralityRejectsPointsBehindCameras) {
  // Two cameras on opposite sides of the ring; the detections are the pinhole images
  // of a point behind camera 0 (x = X/Z ignores the sign of Z), so the two rays meet
  // only behind camera 0 and the algebra alone would accept them.
  const Rig rig = SmallRig(2, /*distortion=*/false);
  const Camera& c0 = rig.cameras[0];
  const Camera& c1 = rig.cameras[1];
  // A point 1 m behind camera 0, off its axis.
  const Eigen::Vector3d behind = c0.CenterInWorld() -
                                 c0.cam_from_world.rotation.row(2).transpose() * 1.0 +
                                 c0.cam_from_world.rotation.row(0).transpose() * 0.1;
  const Eigen::Vector3d in0 = c0.PointInCamera(behind);
  ASSERT_LT(in0.z(), 0);
  // Its pinhole image in camera 0 ignoring the sign of depth, and its image in camera 1.
  const Eigen::Vector2d pix0(c0.fx * in0.x() / in0.z() + c0.cx, c0.fy * in0.y() / in0.z() + c0.cy);
  const auto pix1 = c1.Project(behind);
  ASSERT_TRUE(pix1.has_value());
  std::vector<PointObservation> obs = {{0, pix0, 1.0}, {1, *pix1, 1.0}};
  EXPECT_FALSE(TriangulateRobust(rig, TriangulationOptions(), obs).has_value());
  // Control: the same construction with a point in front of both cameras works.
  const Eigen::Vector3d front(0.05, 0.0, 1.0);
  obs = {{0, *c0.Project(front), 1.0}, {1, *c1.Project(front), 1.0}};
  EXPECT_TRUE(TriangulateRobust(rig, TriangulationOptions(), obs).has_value());
}

TEST(TriangulateRobust, InvariantToCameraOrder) {
  const Rig rig = SmallRig(14);
  std::mt19937 rng(7);
  const Eigen::Vector3d truth(0.25, -0.3, 1.4);
  auto obs = Observe(rig, truth, 1.5, &rng);
  obs[3].pixel += Eigen::Vector2d(80, 0);
  obs[9].pixel += Eigen::Vector2d(0, -200);
  std::uniform_real_distribution<double> u(0.5, 1.0);
  for (auto& o : obs) o.score = u(rng);
  const auto a = TriangulateRobust(rig, TriangulationOptions(), obs);
  // Permute the rig and relabel the observations accordingly.
  std::vector<int> perm(rig.cameras.size());
  for (size_t i = 0; i < perm.size(); ++i) perm[i] = static_cast<int>(perm.size() - 1 - i);
  std::shuffle(perm.begin(), perm.end(), std::mt19937(99));
  Rig permuted = rig;
  for (size_t i = 0; i < perm.size(); ++i) permuted.cameras[perm[i]] = rig.cameras[i];
  auto obs_p = obs;
  for (auto& o : obs_p) o.camera = perm[o.camera];
  std::reverse(obs_p.begin(), obs_p.end());
  const auto b = TriangulateRobust(permuted, TriangulationOptions(), obs_p);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->point_in_world, b->point_in_world);  // bit for bit
  std::vector<int> mapped;
  for (int c : a->inlier_cameras) mapped.push_back(perm[c]);
  std::sort(mapped.begin(), mapped.end());
  EXPECT_EQ(mapped, b->inlier_cameras);
}

TEST(TriangulateRobust, ManyViewsWithManyOutliersStillConverges) {
  const Rig rig = SmallRig(24);
  std::mt19937 rng(8);
  const Eigen::Vector3d truth(0.0, 0.2, 0.9);
  auto obs = Observe(rig, truth, 1.0, &rng);
  std::uniform_real_distribution<double> u(-400, 400);
  for (size_t i = 0; i < obs.size(); i += 3) obs[i].pixel += Eigen::Vector2d(u(rng), 100 + u(rng));
  const auto r = TriangulateRobust(rig, TriangulationOptions(), obs);
  ASSERT_TRUE(r.has_value());
  EXPECT_LT((r->point_in_world - truth).norm(), 2e-3);
  EXPECT_EQ(r->inlier_cameras.size(), 16u);
}

TEST(TriangulateRobust, LeastSquaresRefinementLowersReprojectionError) {
  // With a quadratic loss (huge soft-L1 scale) and equal weights, the refinement
  // minimises exactly the squared reprojection error, so it cannot end above the DLT.
  const Rig rig = SmallRig(6);
  std::mt19937 rng(9);
  double with = 0, without = 0;
  TriangulationOptions l2;
  l2.robust_loss_scale_px = 1e6;
  TriangulationOptions no_refine = l2;
  no_refine.refine = false;
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d truth(0.3 * std::cos(i), 0.3 * std::sin(i), 1.0);
    const auto obs = Observe(rig, truth, 2.0, &rng);
    const auto a = TriangulateRobust(rig, l2, obs);
    const auto b = TriangulateRobust(rig, no_refine, obs);
    ASSERT_TRUE(a && b);
    EXPECT_TRUE(a->refined);
    EXPECT_LE(a->rms_reprojection_px, b->rms_reprojection_px + 1e-9);
    with += a->rms_reprojection_px;
    without += b->rms_reprojection_px;
  }
  EXPECT_LT(with, without);
}

TEST(TriangulateRobust, RobustLossDiscountsAnErrorInsideTheGate) {
  // A 12 px error in one view passes the 15 px gate; the soft-L1 refinement pulls the
  // point less towards it than the least-squares DLT does.
  const Rig rig = SmallRig(5);
  std::mt19937 rng(10);
  double robust = 0, plain = 0;
  TriangulationOptions no_refine;
  no_refine.refine = false;
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d truth(0.2 * std::cos(i), 0.2 * std::sin(i), 1.2);
    auto obs = Observe(rig, truth, 0.2, &rng);
    obs[i % 5].pixel += Eigen::Vector2d(12 * std::cos(i), 12 * std::sin(i));
    const auto a = TriangulateRobust(rig, TriangulationOptions(), obs);
    const auto b = TriangulateRobust(rig, no_refine, obs);
    ASSERT_TRUE(a && b);
    robust += (a->point_in_world - truth).norm();
    plain += (b->point_in_world - truth).norm();
  }
  EXPECT_LT(robust, 0.7 * plain);
}

TEST(TriangulateRobust, CallerBugsThrow) {
  const Rig rig = SmallRig(3);
  std::vector<PointObservation> obs = {{0, {1, 1}, 1}, {7, {1, 1}, 1}};
  EXPECT_THROW(TriangulateRobust(rig, TriangulationOptions(), obs), std::invalid_argument);
  obs = {{0, {1000, 1000}, 1}, {0, {1001, 1000}, 1}};
  EXPECT_THROW(TriangulateRobust(rig, TriangulationOptions(), obs), std::invalid_argument);
  EXPECT_THROW(Triangulator(Rig(), TriangulationOptions()), std::invalid_argument);
}

TEST(TriangulationOptions, ValidateRejectsBadValues) {
  EXPECT_TRUE(TriangulationOptions().Validate().ok());
  auto with = [](auto set) {
    TriangulationOptions o;
    set(o);
    return o.Validate();
  };
  EXPECT_FALSE(with([](auto& o) { o.min_score = 1.5; }).ok());
  EXPECT_FALSE(with([](auto& o) { o.min_score = NAN; }).ok());
  EXPECT_FALSE(with([](auto& o) { o.max_reprojection_px = 0; }).ok());
  EXPECT_FALSE(with([](auto& o) { o.max_ransac_trials = 0; }).ok());
  EXPECT_FALSE(with([](auto& o) { o.ransac_confidence = 1.0; }).ok());
  EXPECT_FALSE(with([](auto& o) { o.robust_loss_scale_px = -1; }).ok());
  EXPECT_FALSE(with([](auto& o) { o.max_refine_iterations = 0; }).ok());
  const Status s = with([](auto& o) { o.max_ransac_trials = 0; });
  EXPECT_NE(s.message().find("max_ransac_trials"), std::string::npos);
  EXPECT_THROW(Triangulator(SmallRig(2),
                            [] {
                              TriangulationOptions o;
                              o.min_score = -1;
                              return o;
                            }()),
               std::invalid_argument);
}

}  // namespace
}  // namespace arco
