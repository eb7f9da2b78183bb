#include "arco/hand/one_view_depth.h"

#include <gtest/gtest.h>

#include <cmath>

namespace arco::hand {
namespace {

Camera FrontCamera() {
  Camera c;
  c.width = 1920, c.height = 1080, c.fx = c.fy = 1500, c.cx = 960, c.cy = 540;
  c.cam_from_world.translation = Eigen::Vector3d(0, 0, 2000);  // the world origin 2 m ahead
  return c;
}

double TipsDepth(const HandModel& model, const Camera& camera, const HandPose& pose) {
  const HandPointsMm points = ForwardKinematics(model, pose);
  std::vector<double> z;
  for (Finger f : {Finger::kIndex, Finger::kMiddle, Finger::kRing, Finger::kLittle})
    z.push_back(camera.PointInCamera(points[TipKeypoint(f)]).z());
  std::sort(z.begin(), z.end());
  return z[2];  // the upper median, as AlignHandDepth takes it
}

TEST(AlignHandDepth, MovesTheHandAlongItsRaysToTheFingertipsDepth) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  const Camera camera = FrontCamera();
  std::vector<std::optional<HandPose>> hands(9);
  std::vector<double> wanted(9);
  for (size_t f = 0; f < hands.size(); ++f) {
    HandPose pose;
    pose.world_from_wrist.translation = Eigen::Vector3d(10.0 * f, -50, 30);
    hands[f] = pose;
    wanted[f] = TipsDepth(model, camera, pose) - 40;  // 40 mm nearer the camera
  }
  wanted[4] += 300;  // one frame's wrong depth: outvoted by the frames around
  hands[7].reset();  // a frame without a hand stays without
  const std::vector<std::optional<HandPose>> before = hands;
  const StatusOr<OneViewDepthSummary> s = AlignHandDepth(model, camera, wanted, {2}, &hands);
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->frames_moved, 8);
  EXPECT_NEAR(s->median_shift_mm, -40, 1e-9);
  EXPECT_FALSE(hands[7].has_value());
  for (size_t f : {0u, 3u, 4u, 8u}) {
    const double moved = TipsDepth(model, camera, *hands[f]) - TipsDepth(model, camera, *before[f]);
    EXPECT_NEAR(moved, -40, 2.0) << "frame " << f;
    // Along the ray: the wrist's image is where it was.
    const auto a = camera.Project(hands[f]->world_from_wrist.translation);
    const auto b = camera.Project(before[f]->world_from_wrist.translation);
    EXPECT_NEAR((*a - *b).norm(), 0, 1e-9);
  }
}

TEST(AlignHandDepth, LeavesHandsWithoutADepthAroundAndRejectsBadInput) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::vector<std::optional<HandPose>> hands(3, HandPose{});
  for (auto& h : hands) h->world_from_wrist.translation = Eigen::Vector3d(0, 0, 100);
  const std::vector<double> none(3, std::nan(""));
  const StatusOr<OneViewDepthSummary> s = AlignHandDepth(model, FrontCamera(), none, {}, &hands);
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(s->frames_moved, 0);
  EXPECT_TRUE(std::isnan(s->median_shift_mm));
  EXPECT_EQ(hands[1]->world_from_wrist.translation, Eigen::Vector3d(0, 0, 100));
  EXPECT_FALSE(AlignHandDepth(model, FrontCamera(), {1.0}, {}, &hands).ok());
  EXPECT_FALSE(AlignHandDepth(model, FrontCamera(), none, {-1}, &hands).ok());
}

}  // namespace
}  // namespace arco::hand
