#include "arco/hand/ray_depth.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "arco/hand/fit.h"
#include "arco/hand/hand_test_util.h"

namespace arco::hand {
namespace {

// The camera 2 m from the hand, looking at it along +z.
const Eigen::Vector3d kCentre(0, 0, -2000);

double MeanError(const HandPointsMm& a, const HandPointsMm& b) {
  double sum = 0;
  for (int k = 0; k < kNumHandKeypoints; ++k) sum += (a[k] - b[k]).norm();
  return sum / kNumHandKeypoints;
}

// The ring and little fingers' keypoints (MCP to tip).
double TiltedFingersError(const HandPointsMm& a, const HandPointsMm& b) {
  double sum = 0;
  for (int k = KeypointIndex(Finger::kRing, 0); k < kNumHandKeypoints; ++k)
    sum += (a[k] - b[k]).norm();
  return sum / 8;
}

// The angle (degrees) between the rays of a and b.
double MaxRayAngleDeg(const HandPointsMm& a, const HandPointsMm& b) {
  double worst = 0;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const double c = (a[k] - kCentre).normalized().dot((b[k] - kCentre).normalized());
    worst = std::max(worst, std::acos(std::min(1.0, c)) * 180.0 / M_PI);
  }
  return worst;
}

// What one view fits: the true hand with its ring and little fingers' keypoints moved
// along their rays toward the camera (a hand tilted in depth, as the real take's one-view
// fit has them), the model fitted to that.
HandPose TiltedInDepth(const HandModel& model, const HandPose& truth, double near_mm) {
  HandPointsMm points = ForwardKinematics(model, truth);
  for (int k = KeypointIndex(Finger::kRing, 0); k < kNumHandKeypoints; ++k) {
    const double along = (k - KeypointIndex(Finger::kRing, 0) + 1) / 8.0;  // more at the tips
    points[k] -= near_mm * along * (points[k] - kCentre).normalized();
  }
  const HandFit3dResult fit = FitHandToPoints3d(model, points, HandFit3dOptions{}, truth);
  EXPECT_TRUE(fit.ok);
  return fit.pose;
}

TEST(PlaceKeypointsAlongRays, TheFingertipsPlacesAlongAnAxisMendTheHandsDepth) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::mt19937 rng(7);
  // The fingertips' places along an axis 35 degrees off the camera's rays (the real take's
  // camera to the strings), the truth's, within 1 mm.
  const Eigen::Vector3d axis =
      Eigen::Vector3d(std::sin(35 * M_PI / 180), 0, std::cos(35 * M_PI / 180));
  double before = 0, after = 0, fingers_before = 0, fingers_after = 0, worst_angle = 0;
  const int trials = 12;
  for (int t = 0; t < trials; ++t) {
    const HandPose truth = testing::RandomPose(model, rng, 0.15);
    const HandPose seen = TiltedInDepth(model, truth, 40.0);
    const HandPointsMm want = ForwardKinematics(model, truth);
    std::vector<AxisTarget> targets;
    for (Finger f : {Finger::kIndex, Finger::kMiddle, Finger::kRing, Finger::kLittle}) {
      targets.push_back({TipKeypoint(f), axis, axis.dot(want[TipKeypoint(f)]), 1.0});
    }
    const std::optional<RayDepthResult> placed =
        PlaceKeypointsAlongRays(model, kCentre, seen, targets, RayDepthOptions{});
    ASSERT_TRUE(placed.has_value());
    const HandPointsMm got = ForwardKinematics(model, placed->pose);
    before += MeanError(ForwardKinematics(model, seen), want) / trials;
    after += MeanError(got, want) / trials;
    fingers_before += TiltedFingersError(ForwardKinematics(model, seen), want) / trials;
    fingers_after += TiltedFingersError(got, want) / trials;
    worst_angle = std::max(worst_angle, MaxRayAngleDeg(got, ForwardKinematics(model, seen)));
    EXPECT_GT(placed->median_move_mm, 0.0);
  }
  std::printf(
      "[ rays ] the hand's mean keypoint error %.1f -> %.1f mm (ring and little %.1f -> %.1f), "
      "rays turned <= %.2f deg\n",
      before,
      after,
      fingers_before,
      fingers_after,
      worst_angle);
  EXPECT_GT(fingers_before, 10.0);
  EXPECT_LT(fingers_after, 0.5 * fingers_before);
  EXPECT_LT(after, 0.6 * before);
  // Along the rays: the image barely moves (the model's refit, under 1 degree at 2 m).
  EXPECT_LT(worst_angle, 1.0);
}

TEST(PlaceKeypointsAlongRays, NoTargetsLeaveTheHandWhereItIs) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::mt19937 rng(3);
  const HandPose pose = testing::RandomPose(model, rng, 0.15);
  const std::optional<RayDepthResult> placed =
      PlaceKeypointsAlongRays(model, kCentre, pose, {}, RayDepthOptions{});
  ASSERT_TRUE(placed.has_value());
  EXPECT_LT(MeanError(ForwardKinematics(model, placed->pose), ForwardKinematics(model, pose)), 0.5);
}

TEST(PlaceKeypointsAlongRays, RejectsTargetsThatNameNothing) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  const HandPose pose;
  const RayDepthOptions o;
  EXPECT_FALSE(
      PlaceKeypointsAlongRays(model, kCentre, pose, {{21, Eigen::Vector3d::UnitX(), 0, 1}}, o));
  EXPECT_FALSE(
      PlaceKeypointsAlongRays(model, kCentre, pose, {{8, Eigen::Vector3d(2, 0, 0), 0, 1}}, o));
  EXPECT_FALSE(
      PlaceKeypointsAlongRays(model, kCentre, pose, {{8, Eigen::Vector3d::UnitX(), 0, 0}}, o));
  EXPECT_FALSE(
      PlaceKeypointsAlongRays(model, kCentre, pose, {{8, Eigen::Vector3d::UnitX(), NAN, 1}}, o));
  // A hand at the camera's centre has no rays.
  EXPECT_FALSE(PlaceKeypointsAlongRays(model, Eigen::Vector3d::Zero(), pose, {}, o));
}

TEST(RayDepthOptions, DeclaredRanges) {
  RayDepthOptions o;
  EXPECT_TRUE(o.Validate().ok());
  o.bone_sigma_mm = 0;
  EXPECT_FALSE(o.Validate().ok());
  o = RayDepthOptions{};
  o.stay_sigma_mm = -1;
  EXPECT_FALSE(o.Validate().ok());
  o = RayDepthOptions{};
  o.max_iterations = 0;
  EXPECT_FALSE(o.Validate().ok());
}

}  // namespace
}  // namespace arco::hand
