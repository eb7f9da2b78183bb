// BowTracker on a textured stick splatted exactly into three distorted cameras: found
// after a move, and its scores drop (and its views say lost) when the bow is gone.
#include "arco/track/bow_tracker.h"

#include <gtest/gtest.h>

#include <cmath>
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
    // Cameras on an arc at 2.5 m looking at the origin, at three heights.
    const double a = (i - 1) * 0.6;
    const Eigen::Vector3d centre(2500 * std::sin(a), -2500 * std::cos(a), 300.0 * (i - 1));
    const Eigen::Matrix3d r = testing::CamFromWorldLookingAt(centre, Eigen::Vector3d::Zero());
    c.cam_from_world.rotation = r;
    c.cam_from_world.translation = -r * centre;
    cams.push_back(c);
  }
  return cams;
}

// A 720 x 24 mm stick along x (frog at u = 20 mm, tip at u = 700 mm from its end) with
// random 20 mm grey blocks, its plane facing -y, shifted by `offset`: every pixel it
// covers gets its block's grey (splatted at 0.25 mm, well under a pixel).
media::Image Render(const Camera& cam, const Eigen::Vector3d& offset, bool with_bow) {
  media::Image image = media::MakeImage(cam.width, cam.height, media::PixelFormat::kGray8);
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) image.row(y)[x] = static_cast<uint8_t>(90 + (x / 40) % 3);
  if (!with_bow) return image;
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> grey(20, 240);
  std::vector<uint8_t> blocks(36);
  for (auto& b : blocks) b = static_cast<uint8_t>(grey(rng));
  for (double u = 0; u < 720; u += 0.25)
    for (double w = -12; w <= 12; w += 0.25) {
      const Eigen::Vector3d x = offset + Eigen::Vector3d(u - 360, 0, w);
      const auto p = cam.Project(x);
      if (!p) continue;
      const int px = static_cast<int>(std::lround(p->x())),
                py = static_cast<int>(std::lround(p->y()));
      if (px < 0 || py < 0 || px >= cam.width || py >= cam.height) continue;
      image.row(py)[px] = blocks[static_cast<int>(u / 20)];
    }
  return image;
}

const Eigen::Vector3d kFrog(20 - 360, 0, 0), kTip(700 - 360, 0, 0);

std::vector<const media::Image*> Pointers(const std::vector<media::Image>& images) {
  std::vector<const media::Image*> out;
  for (const auto& i : images) out.push_back(&i);
  return out;
}

TEST(BowTracker, FindsTheBowAfterAMove) {
  const std::vector<Camera> cams = Rig3();
  std::vector<media::Image> start, moved;
  const Eigen::Vector3d offset(18, 6, -5);
  for (const Camera& c : cams) {
    start.push_back(Render(c, Eigen::Vector3d::Zero(), true));
    moved.push_back(Render(c, offset, true));
  }
  BowTracker tracker(cams, kFrog, kTip, BowTrackerOptions{});
  const TrackFrame first = tracker.Start(Pointers(start));
  EXPECT_TRUE(first.pose_ok);
  const TrackFrame r = tracker.Next(Pointers(moved));
  ASSERT_TRUE(r.pose_ok);
  EXPECT_GT(r.match_ncc, 0.5);
  for (size_t v = 0; v < cams.size(); ++v) {
    EXPECT_FALSE(r.views[v].lost);
    EXPECT_GT(r.views[v].inliers, 0);
    for (int p = 0; p < 2; ++p) {
      const Eigen::Vector2d truth = *cams[v].Project((p == 0 ? kFrog : kTip) + offset);
      EXPECT_LT((r.points[v][p].pixel - truth).norm(), 2.0) << "view " << v << " point " << p;
      EXPECT_GT(r.points[v][p].score, 0.5);
    }
  }
}

TEST(BowTracker, ScoresDropWhenTheBowIsGone) {
  const std::vector<Camera> cams = Rig3();
  std::vector<media::Image> start, empty;
  for (const Camera& c : cams) {
    start.push_back(Render(c, Eigen::Vector3d::Zero(), true));
    empty.push_back(Render(c, Eigen::Vector3d::Zero(), false));
  }
  BowTracker tracker(cams, kFrog, kTip, BowTrackerOptions{});
  tracker.Start(Pointers(start));
  const TrackFrame r = tracker.Next(Pointers(empty));
  EXPECT_FALSE(r.pose_ok);
  for (size_t v = 0; v < cams.size(); ++v) {
    EXPECT_TRUE(r.views[v].lost);
    for (int p = 0; p < 2; ++p) {
      EXPECT_TRUE(std::isfinite(r.points[v][p].pixel.x()));  // still placed (predicted)
      EXPECT_LE(r.points[v][p].score, 0.1);
    }
  }
  // And found again when it comes back.
  const TrackFrame back = tracker.Next(Pointers(start));
  EXPECT_TRUE(back.pose_ok);
  for (size_t v = 0; v < cams.size(); ++v) EXPECT_TRUE(back.views[v].reacquired);
}

// The bow jumps 130 mm along itself between two frames, beyond the slide search (40 mm)
// and the texture's reach from the prediction: without the hand it is lost or misplaced;
// with the right hand seen in the views (held at its labelled-frame offset from the frog)
// it is found again.
TEST(BowTracker, TheRightHandBringsBackABowThatJumped) {
  const std::vector<Camera> cams = Rig3();
  const Eigen::Vector3d jump(130, 8, -6), hand_offset(40, -15, 10);
  std::vector<media::Image> start, moved;
  std::vector<Eigen::Vector2d> hand_start, hand_moved;
  for (const Camera& c : cams) {
    start.push_back(Render(c, Eigen::Vector3d::Zero(), true));
    moved.push_back(Render(c, jump, true));
    hand_start.push_back(*c.Project(kFrog + hand_offset));
    // A hand detector's error: a few pixels.
    hand_moved.push_back(*c.Project(kFrog + jump + hand_offset) + Eigen::Vector2d(3, -2));
  }
  const auto worst_px = [&](const TrackFrame& r) {
    double worst = 0;
    for (size_t v = 0; v < cams.size(); ++v)
      for (int p = 0; p < 2; ++p) {
        const Eigen::Vector2d truth = *cams[v].Project((p == 0 ? kFrog : kTip) + jump);
        worst = std::max(worst, (r.points[v][p].pixel - truth).norm());
      }
    return worst;
  };
  {
    BowTracker tracker(cams, kFrog, kTip, BowTrackerOptions{});
    tracker.Start(Pointers(start));
    const TrackFrame r = tracker.Next(Pointers(moved));
    EXPECT_TRUE(!r.pose_ok || worst_px(r) > 10) << worst_px(r);
  }
  BowTracker tracker(cams, kFrog, kTip, BowTrackerOptions{});
  tracker.Start(Pointers(start), &hand_start);
  const TrackFrame r = tracker.Next(Pointers(moved), nullptr, &hand_moved);
  EXPECT_TRUE(r.pose_ok);
  EXPECT_LT(worst_px(r), 2.0);
}

// Views in parallel: the same result, bit for bit.
TEST(BowTracker, TheSameForAnyThreadCount) {
  const std::vector<Camera> cams = Rig3();
  std::vector<media::Image> start, moved;
  for (const Camera& c : cams) {
    start.push_back(Render(c, Eigen::Vector3d::Zero(), true));
    moved.push_back(Render(c, Eigen::Vector3d(-21, 4, 7), true));
  }
  std::vector<TrackFrame> results;
  for (int threads : {1, 3}) {
    BowTrackerOptions o;
    o.num_threads = threads;
    BowTracker tracker(cams, kFrog, kTip, o);
    tracker.Start(Pointers(start));
    results.push_back(tracker.Next(Pointers(moved)));
  }
  for (size_t v = 0; v < cams.size(); ++v)
    for (int p = 0; p < 2; ++p) {
      EXPECT_EQ(results[0].points[v][p].pixel.x(), results[1].points[v][p].pixel.x());
      EXPECT_EQ(results[0].points[v][p].pixel.y(), results[1].points[v][p].pixel.y());
    }
  EXPECT_EQ(results[0].match_ncc, results[1].match_ncc);
}

TEST(BowTracker, RejectsAShortBowAndBadOptions) {
  EXPECT_THROW(BowTracker(Rig3(), kFrog, kFrog + Eigen::Vector3d(10, 0, 0), BowTrackerOptions{}),
               std::invalid_argument);
  BowTrackerOptions o;
  o.max_angle_deg = 0;
  EXPECT_THROW(BowTracker(Rig3(), kFrog, kTip, o), std::invalid_argument);
}

}  // namespace
}  // namespace arco::track
