#include "arco/hand/one_view_depth.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace arco::hand {
namespace {

// The camera 2 m from the world's origin, looking at it along +z.
const Eigen::Vector3d kCentre(0, 0, -2000);

Eigen::Vector2d Image(const Eigen::Vector3d& p) {
  const Eigen::Vector3d q = p - kCentre;
  return q.head<2>() / q.z();
}

double TipsDistance(const HandModel& model, const HandPose& pose) {
  const HandPointsMm points = ForwardKinematics(model, pose);
  std::vector<double> d;
  for (Finger f : {Finger::kIndex, Finger::kMiddle, Finger::kRing, Finger::kLittle})
    d.push_back((points[TipKeypoint(f)] - kCentre).norm());
  std::sort(d.begin(), d.end());
  return d[2];  // the upper median, as AlignHandDepth takes it
}

TEST(AlignHandDepth, MovesTheHandAlongItsRaysToTheFingertipsDepth) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::vector<std::optional<HandPose>> hands(9);
  std::vector<double> wanted(9);
  for (size_t f = 0; f < hands.size(); ++f) {
    HandPose pose;
    pose.world_from_wrist.translation = Eigen::Vector3d(10.0 * f, -50, 30);
    hands[f] = pose;
    wanted[f] = TipsDistance(model, pose) - 40;  // 40 mm nearer the camera
  }
  wanted[4] += 300;  // one frame's wrong depth: outvoted by the frames around
  hands[7].reset();  // a frame without a hand stays without
  const std::vector<std::optional<HandPose>> before = hands;
  const StatusOr<OneViewDepthSummary> s = AlignHandDepth(model, kCentre, wanted, {2}, &hands);
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->frames_moved, 8);
  // The frames' own distances differ by up to 2 mm (the hand moves across the image), and
  // each frame takes the median of the wanted distances around it.
  EXPECT_NEAR(s->median_shift_mm, -40, 2.0);
  EXPECT_FALSE(hands[7].has_value());
  for (size_t f : {0u, 3u, 4u, 8u}) {
    const double moved = TipsDistance(model, *hands[f]) - TipsDistance(model, *before[f]);
    EXPECT_NEAR(moved, -40, 2.0) << "frame " << f;
    // Along the ray: the wrist's image is where it was.
    EXPECT_NEAR((Image(hands[f]->world_from_wrist.translation) -
                 Image(before[f]->world_from_wrist.translation))
                    .norm(),
                0,
                1e-12);
  }
}

// A one-view fit's depth jitters from frame to frame (a few pixels of the hand's size in
// the image); where the wanted distance is steady, every frame's hand goes to it, the
// jitter gone to under a millimetre (a median of the shifts instead would keep it).
TEST(AlignHandDepth, TheFitsOwnDepthJitterIsRemoved) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::vector<std::optional<HandPose>> hands(31);
  std::vector<double> wanted(hands.size());
  for (size_t f = 0; f < hands.size(); ++f) {
    HandPose pose;
    const double jitter_mm = (f % 2 ? 25.0 : -25.0) * std::sin(0.7 * f);
    pose.world_from_wrist.translation = Eigen::Vector3d(0, -50, 30 + jitter_mm);
    hands[f] = pose;
    wanted[f] = 1950;
  }
  ASSERT_TRUE(AlignHandDepth(model, kCentre, wanted, {15}, &hands).ok());
  double worst = 0;
  for (const auto& h : hands) worst = std::max(worst, std::abs(TipsDistance(model, *h) - 1950));
  EXPECT_LT(worst, 1.0);  // +-25 mm of jitter; the tips move by the cosine of the rays' angle
}

TEST(AlignHandDepth, LeavesHandsWithoutADepthAroundAndRejectsBadInput) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::vector<std::optional<HandPose>> hands(3, HandPose{});
  for (auto& h : hands) h->world_from_wrist.translation = Eigen::Vector3d(0, 0, 100);
  const std::vector<double> none(3, std::nan(""));
  const StatusOr<OneViewDepthSummary> s = AlignHandDepth(model, kCentre, none, {}, &hands);
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(s->frames_moved, 0);
  EXPECT_TRUE(std::isnan(s->median_shift_mm));
  EXPECT_EQ(hands[1]->world_from_wrist.translation, Eigen::Vector3d(0, 0, 100));
  EXPECT_FALSE(AlignHandDepth(model, kCentre, {1.0}, {}, &hands).ok());
  EXPECT_FALSE(AlignHandDepth(model, kCentre, none, {-1}, &hands).ok());
  EXPECT_FALSE(MoveHandsAlongRays(kCentre, {1.0}, {}, &hands).ok());
}

}  // namespace
}  // namespace arco::hand
