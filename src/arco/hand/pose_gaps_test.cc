#include "arco/hand/pose_gaps.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

namespace arco::hand {
namespace {

HandPose Pose(double angle, double yaw_rad, double x_mm) {
  HandPose p;
  for (size_t d = 0; d < p.angles_rad.size(); ++d) p.angles_rad[d] = angle + 0.01 * d;
  p.world_from_wrist.rotation =
      Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  p.world_from_wrist.translation = Eigen::Vector3d(x_mm, 2 * x_mm, 100);
  return p;
}

double Yaw(const HandPose& p) {
  const Eigen::Matrix3d& r = p.world_from_wrist.rotation;
  return std::atan2(r(1, 0), r(0, 0));
}

TEST(FillHandPoseGaps, AShortGapIsInterpolatedBetweenItsFittedNeighbours) {
  std::vector<std::optional<HandPose>> hands(5);
  hands[0] = Pose(0.1, 0.0, 0.0);
  hands[4] = Pose(0.5, 0.8, 40.0);
  const StatusOr<int> filled = FillHandPoseGaps({}, &hands);
  ASSERT_TRUE(filled.ok()) << filled.status().message();
  EXPECT_EQ(*filled, 3);
  for (int g = 1; g <= 3; ++g) {
    ASSERT_TRUE(hands[static_cast<size_t>(g)].has_value()) << g;
    const HandPose& p = *hands[static_cast<size_t>(g)];
    const double t = g / 4.0;
    for (size_t d = 0; d < p.angles_rad.size(); ++d)
      EXPECT_NEAR(p.angles_rad[d], 0.1 + 0.4 * t + 0.01 * d, 1e-12) << g << " " << d;
    // The wrist turns at a constant rate about the one axis (slerp) and moves on the line.
    EXPECT_NEAR(Yaw(p), 0.8 * t, 1e-12) << g;
    EXPECT_NEAR((p.world_from_wrist.rotation.transpose() * p.world_from_wrist.rotation -
                 Eigen::Matrix3d::Identity())
                    .norm(),
                0.0,
                1e-12);
    EXPECT_NEAR(
        (p.world_from_wrist.translation - Eigen::Vector3d(40 * t, 80 * t, 100)).norm(), 0.0, 1e-12);
  }
}

TEST(FillHandPoseGaps, LongGapsAndTheTakesEndsStayEmpty) {
  std::vector<std::optional<HandPose>> hands(14);
  hands[1] = Pose(0.1, 0.0, 0.0);
  hands[7] = Pose(0.2, 0.1, 5.0);   // a gap of 5 (2-6): filled
  hands[13] = Pose(0.3, 0.2, 9.0);  // a gap of 5 after it too
  hands[13].reset();
  hands[12] = Pose(0.3, 0.2, 9.0);  // gap 8-11 (4): filled; 13 and 0 are ends
  std::vector<std::optional<HandPose>> far = hands;
  PoseGapOptions options;
  const StatusOr<int> filled = FillHandPoseGaps(options, &hands);
  ASSERT_TRUE(filled.ok());
  EXPECT_EQ(*filled, 9);
  EXPECT_FALSE(hands[0].has_value());
  EXPECT_FALSE(hands[13].has_value());
  for (int f = 1; f <= 12; ++f) EXPECT_TRUE(hands[static_cast<size_t>(f)].has_value()) << f;
  // Shorter limits: the gap of 5 stays, the gap of 4 is filled; 0 fills nothing.
  options.max_gap_frames = 4;
  std::vector<std::optional<HandPose>> four = far;
  ASSERT_EQ(*FillHandPoseGaps(options, &four), 4);
  EXPECT_FALSE(four[4].has_value());
  EXPECT_TRUE(four[10].has_value());
  options.max_gap_frames = 0;
  std::vector<std::optional<HandPose>> none = far;
  ASSERT_EQ(*FillHandPoseGaps(options, &none), 0);
  for (size_t f = 0; f < none.size(); ++f) EXPECT_EQ(none[f].has_value(), far[f].has_value());
}

TEST(FillHandPoseGaps, OptionsOutsideTheirRangeAreErrors) {
  std::vector<std::optional<HandPose>> hands(3);
  PoseGapOptions options;
  options.max_gap_frames = -1;
  EXPECT_FALSE(FillHandPoseGaps(options, &hands).ok());
  options.max_gap_frames = 1001;
  EXPECT_FALSE(FillHandPoseGaps(options, &hands).ok());
}

}  // namespace
}  // namespace arco::hand
