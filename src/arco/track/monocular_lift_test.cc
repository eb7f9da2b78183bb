// LiftOneView on generated views of known truth: an instrument-like rigid body posed in
// front of one camera (with distortion), a hand whose fingertips lie on its strings, body
// points with no depth cue, and a bow left unlifted.
#include "arco/track/monocular_lift.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "arco/testing/look_at.h"

namespace arco::track {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Columns: 0-6 the instrument, 7-10 fingertips, 11 a wrist, 12 a shoulder, 13 the bow.
constexpr int kPoints = 14;

struct World {
  Camera camera;
  MonocularScene scene;
  std::vector<Rigid3d> world_from_instrument;  // per frame
  std::vector<std::array<Eigen::Vector3d, kPoints>> truth;
  NpyArray<double> keypoints;  // (F, 1, P, 3)
};

// `sway`: the instrument turns and slides a little from frame to frame (else held still);
// `approach_mm_per_frame`: it comes nearer the camera by this much per frame.
World MakeWorld(int frames, bool sway = true, double approach_mm_per_frame = 0) {
  World w;
  Camera& c = w.camera;
  c.width = 1920, c.height = 1080, c.fx = c.fy = 1500, c.cx = 960, c.cy = 540;
  c.distortion.k1 = -0.05;
  const Eigen::Vector3d centre(0, -2500, 800);
  c.cam_from_world.rotation = testing::CamFromWorldLookingAt(centre, Eigen::Vector3d(0, 0, 700));
  c.cam_from_world.translation = -c.cam_from_world.rotation * centre;
  // A cello-sized body: strings along x, the front +z, points off the string plane.
  MonocularScene& s = w.scene;
  s.instrument_points_mm = {{881, 0, -25},
                            {695, 12, 0},
                            {695, -12, 0},
                            {0, 24, 0},
                            {0, -24, 0},
                            {-377, 0, -75},
                            {-691, 0, -120}};
  for (int i = 0; i < 7; ++i) s.instrument_columns.push_back(i);
  for (int i = 0; i < 4; ++i) {
    const double f = i / 3.0;
    s.strings_mm.emplace_back(Eigen::Vector3d(695, 12 - 24 * f, 0),
                              Eigen::Vector3d(0, 24 - 48 * f, 0));
  }
  s.string_line_columns = {7, 8, 9, 10, 11};
  s.string_line_depth_columns = {7, 8, 9, 10};
  s.unlifted_columns = {13};
  w.keypoints.shape = {frames, 1, kPoints, 3};
  w.keypoints.data.assign(static_cast<size_t>(frames * kPoints * 3), kNaN);
  for (int f = 0; f < frames; ++f) {
    // Upright (strings up the world z), facing the camera (-y), swaying a little.
    const double a = sway ? 0.02 * std::sin(0.3 * f) : 0.0;
    Eigen::Matrix3d r;
    r.col(0) = Eigen::Vector3d(std::sin(a), 0, std::cos(a));  // x: up
    r.col(2) = Eigen::Vector3d(0, -1, 0);                     // z: to the camera
    r.col(1) = r.col(2).cross(r.col(0));
    w.world_from_instrument.push_back(
        Rigid3d(r, Eigen::Vector3d(sway ? 3.0 * f : 0.0, -approach_mm_per_frame * f, 300)));
    const Rigid3d& pose = w.world_from_instrument.back();
    std::array<Eigen::Vector3d, kPoints> x;
    for (int i = 0; i < 7; ++i) x[i] = pose * s.instrument_points_mm[i];
    // Fingertips on strings 1-4 at 500 mm from the bridge; a wrist 60 mm behind them; a
    // shoulder 300 mm behind the instrument; a bow frog in front.
    for (int i = 0; i < 4; ++i)
      x[7 + i] = pose * (s.strings_mm[i].second +
                         500.0 / 695 * (s.strings_mm[i].first - s.strings_mm[i].second));
    x[11] = pose * Eigen::Vector3d(480, 40, -60);
    x[12] = pose * Eigen::Vector3d(600, 0, -300);
    x[13] = pose * Eigen::Vector3d(100, 0, 200);
    w.truth.push_back(x);
    for (int p = 0; p < kPoints; ++p) {
      const std::optional<Eigen::Vector2d> px = c.Project(x[p]);
      EXPECT_TRUE(px.has_value());
      w.keypoints.at(f, 0, p, 0) = px->x();
      w.keypoints.at(f, 0, p, 1) = px->y();
      w.keypoints.at(f, 0, p, 2) = 0.9;
    }
  }
  return w;
}

// Gaussian pixel noise (sigma_px) on the instrument's points, columns 0-6.
void AddInstrumentNoise(double sigma_px, unsigned seed, World* w) {
  std::mt19937 random(seed);
  std::normal_distribution<double> noise(0.0, sigma_px);
  const int64_t frames = w->keypoints.shape[0];
  for (int64_t f = 0; f < frames; ++f) {
    for (int p = 0; p < 7; ++p) {
      for (int c = 0; c < 2; ++c) w->keypoints.at(f, 0, p, c) += noise(random);
    }
  }
}

TEST(LiftOneView, PlacesTheInstrumentAndTheHandAtTheirDepthsAndFlagsTheRest) {
  const World w = MakeWorld(20);
  MonocularLiftOptions o;
  o.depth_window_frames = 3;
  o.rotation_window_frames = 0;  // the sway's turn is exact in each frame's own PnP
  const StatusOr<MonocularLift> lift = LiftOneView(w.camera, w.keypoints, w.scene, o);
  ASSERT_TRUE(lift.ok()) << lift.status().message();
  EXPECT_EQ(lift->summary.frames_with_pose, 20);
  EXPECT_LT(lift->summary.median_pnp_rms_px, 1e-3);
  for (int f = 0; f < 20; ++f) {
    auto at = [&](int p) {
      return Eigen::Vector3d(lift->points3d_mm.at(f, p, 0),
                             lift->points3d_mm.at(f, p, 1),
                             lift->points3d_mm.at(f, p, 2));
    };
    // Exact pixels: the instrument to within 10 micrometres, each point from its pose (the
    // sway moves its depth by micrometres, which the median over 3 frames lags).
    for (int p = 0; p < 7; ++p) {
      EXPECT_LT((at(p) - w.truth[f][p]).norm(), 1e-2) << "frame " << f << " point " << p;
      EXPECT_EQ(lift->depth_source.at(f, p), static_cast<uint8_t>(LiftDepth::kInstrumentPose));
    }
    // The fingertips on the strings: the hand's depth is theirs (one depth for the hand).
    for (int p = 7; p <= 11; ++p)
      EXPECT_EQ(lift->depth_source.at(f, p), static_cast<uint8_t>(LiftDepth::kStringLine));
    const Eigen::Vector3d tip = w.camera.PointInCamera(at(8));
    EXPECT_NEAR(tip.z(), w.camera.PointInCamera(w.truth[f][8]).z(), 1.0);
    // Every lifted point lies on its own pixel's ray.
    for (int p : {8, 11, 12}) {
      const std::optional<Eigen::Vector2d> px = w.camera.Project(at(p));
      ASSERT_TRUE(px.has_value());
      EXPECT_NEAR(px->x(), w.keypoints.at(f, 0, p, 0), 1e-6);
      EXPECT_NEAR(px->y(), w.keypoints.at(f, 0, p, 1), 1e-6);
    }
    // The shoulder: an assumed depth, flagged; the bow: not lifted.
    EXPECT_EQ(lift->depth_source.at(f, 12), static_cast<uint8_t>(LiftDepth::kAssumedPlane));
    EXPECT_EQ(lift->depth_source.at(f, 13), static_cast<uint8_t>(LiftDepth::kNone));
    EXPECT_TRUE(std::isnan(lift->points3d_mm.at(f, 13, 0)));
  }
}

TEST(LiftOneView, SmoothsTheInstrumentsDepthOverTheFramesAround) {
  World w = MakeWorld(21);
  // Frame 10's instrument pixels scaled about their centroid by 2 %: alone, a PnP puts the
  // instrument 2 % nearer (about 50 mm); the median of its neighbours puts it back.
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (int p = 0; p < 7; ++p)
    mean += Eigen::Vector2d(w.keypoints.at(10, 0, p, 0), w.keypoints.at(10, 0, p, 1));
  mean /= 7;
  for (int p = 0; p < 7; ++p) {
    for (int c = 0; c < 2; ++c)
      w.keypoints.at(10, 0, p, c) = mean[c] + 1.02 * (w.keypoints.at(10, 0, p, c) - mean[c]);
  }
  auto depth_error = [&](int window) {
    MonocularLiftOptions o;
    o.depth_window_frames = window;
    o.pnp_gate_px = 20;
    const StatusOr<MonocularLift> lift = LiftOneView(w.camera, w.keypoints, w.scene, o);
    EXPECT_TRUE(lift.ok());
    const Eigen::Vector3d bridge(lift->points3d_mm.at(10, 3, 0),
                                 lift->points3d_mm.at(10, 3, 1),
                                 lift->points3d_mm.at(10, 3, 2));
    return std::abs(w.camera.PointInCamera(bridge).z() -
                    w.camera.PointInCamera(w.truth[10][3]).z());
  };
  EXPECT_GT(depth_error(0), 30.0);
  EXPECT_LT(depth_error(5), 5.0);
}

// A detector's error on the instrument's points lasts seconds (a slow drift), and one view
// reads the depth from the instrument's size in the image: pixels 2 % larger put it 2 %
// nearer (50 mm). Over a still instrument the pixels here swell and shrink by 2 % with a
// period of 2 s (60 frames at 30 fps): the default window (+-90 frames) holds the depth,
// the former +-15 followed the drift. A real move, the instrument coming 30 mm/s nearer
// over 10 s, is still followed.
TEST(LiftOneView, HoldsTheInstrumentsDepthThroughTheDetectorsSlowDrift) {
  constexpr int kFrames = 301;
  auto drifted = [](World w) {
    for (int f = 0; f < kFrames; ++f) {
      Eigen::Vector2d mean = Eigen::Vector2d::Zero();
      for (int p = 0; p < 7; ++p)
        mean += Eigen::Vector2d(w.keypoints.at(f, 0, p, 0), w.keypoints.at(f, 0, p, 1));
      mean /= 7;
      const double scale = 1 + 0.02 * std::sin(2 * M_PI * f / 60.0);
      for (int p = 0; p < 7; ++p) {
        for (int c = 0; c < 2; ++c)
          w.keypoints.at(f, 0, p, c) = mean[c] + scale * (w.keypoints.at(f, 0, p, c) - mean[c]);
      }
    }
    return w;
  };
  // The largest error of the bridge's depth over the middle frames (a window's median is
  // one-sided at the ends).
  auto worst_depth_error = [&](const World& w, int window) {
    MonocularLiftOptions o;
    if (window >= 0) o.depth_window_frames = window;
    o.pnp_gate_px = 20;
    const StatusOr<MonocularLift> lift = LiftOneView(w.camera, w.keypoints, w.scene, o);
    EXPECT_TRUE(lift.ok());
    double worst = 0;
    for (int f = 100; f <= 200; ++f) {
      const Eigen::Vector3d bridge(lift->points3d_mm.at(f, 3, 0),
                                   lift->points3d_mm.at(f, 3, 1),
                                   lift->points3d_mm.at(f, 3, 2));
      worst = std::max(
          worst,
          std::abs(w.camera.PointInCamera(bridge).z() - w.camera.PointInCamera(w.truth[f][3]).z()));
    }
    return worst;
  };
  const World still = drifted(MakeWorld(kFrames, /*sway=*/false));
  const World coming = MakeWorld(kFrames, /*sway=*/false, /*approach_mm_per_frame=*/1.0);
  const double held = worst_depth_error(still, -1), followed = worst_depth_error(still, 15),
               moved = worst_depth_error(coming, -1);
  std::printf(
      "[ one view ] depth error through a slow drift: %.1f mm (+-15 frames: %.1f mm); "
      "an instrument coming nearer: %.1f mm\n",
      held,
      followed,
      moved);
  EXPECT_LT(held, 10.0);  // the default
  EXPECT_GT(followed, 25.0);
  EXPECT_LT(moved, 2.0);
}

// A cello stands on its end pin (MonocularScene::stands_on_end_pin): its depth is held
// over MonocularLiftOptions::end_pin_depth_window_frames (+-250), through a detector's
// drift that lasts the take: here the pixels swell by up to 3 % over 20 s (a quarter of
// it in the take's 10 s), which the held instrument's +-90 follows in part.
TEST(LiftOneView, HoldsAnEndPinInstrumentsDepthOverTheTake) {
  constexpr int kFrames = 301;
  World w = MakeWorld(kFrames, /*sway=*/false);
  for (int f = 0; f < kFrames; ++f) {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (int p = 0; p < 7; ++p)
      mean += Eigen::Vector2d(w.keypoints.at(f, 0, p, 0), w.keypoints.at(f, 0, p, 1));
    mean /= 7;
    const double scale = 1 + 0.03 * std::sin(2 * M_PI * (f - 150) / 600.0);
    for (int p = 0; p < 7; ++p) {
      for (int c = 0; c < 2; ++c)
        w.keypoints.at(f, 0, p, c) = mean[c] + scale * (w.keypoints.at(f, 0, p, c) - mean[c]);
    }
  }
  auto mean_depth_error = [&](bool end_pin) {
    MonocularScene scene = w.scene;
    scene.stands_on_end_pin = end_pin;
    MonocularLiftOptions o;
    o.pnp_gate_px = 20;
    const StatusOr<MonocularLift> lift = LiftOneView(w.camera, w.keypoints, scene, o);
    EXPECT_TRUE(lift.ok());
    double sum = 0;
    for (int f = 0; f < kFrames; ++f) {
      const Eigen::Vector3d bridge(lift->points3d_mm.at(f, 3, 0),
                                   lift->points3d_mm.at(f, 3, 1),
                                   lift->points3d_mm.at(f, 3, 2));
      sum +=
          std::abs(w.camera.PointInCamera(bridge).z() - w.camera.PointInCamera(w.truth[f][3]).z());
    }
    return sum / kFrames;
  };
  const double held = mean_depth_error(false), end_pin = mean_depth_error(true);
  std::printf(
      "[ one view ] depth error through a drift over the take: %.1f mm held (+-90), "
      "%.1f mm on its end pin (+-250)\n",
      held,
      end_pin);
  EXPECT_LT(end_pin, 0.6 * held);
  MonocularLiftOptions bad;
  bad.end_pin_depth_window_frames = 3001;
  EXPECT_FALSE(bad.Validate().ok());
  bad.end_pin_depth_window_frames = -1;
  EXPECT_FALSE(bad.Validate().ok());
}

TEST(LiftOneView, SaysHowFarTheInstrumentsDepthMayBeOff) {
  // Exact pixels: the frames' own depths agree, nothing is uncertain. Two pixels of
  // noise: the frames' depths spread by centimetres and the spread is reported; the
  // actual error of the window's median lies within two of it in most frames.
  const World exact = MakeWorld(31, /*sway=*/false);
  const StatusOr<MonocularLift> a = LiftOneView(exact.camera, exact.keypoints, exact.scene, {});
  ASSERT_TRUE(a.ok());
  ASSERT_EQ(a->depth_sigma_mm.shape, std::vector<int64_t>{31});
  for (float sigma : a->depth_sigma_mm.data) EXPECT_LT(sigma, 0.1);
  World noisy = MakeWorld(31, /*sway=*/false);
  AddInstrumentNoise(2.0, /*seed=*/3, &noisy);
  const StatusOr<MonocularLift> b = LiftOneView(noisy.camera, noisy.keypoints, noisy.scene, {});
  ASSERT_TRUE(b.ok());
  int within = 0;
  for (int f = 0; f < 31; ++f) {
    const float sigma = b->depth_sigma_mm.data[f];
    EXPECT_GT(sigma, 5.0) << "frame " << f;
    const Eigen::Vector3d bridge(
        b->points3d_mm.at(f, 3, 0), b->points3d_mm.at(f, 3, 1), b->points3d_mm.at(f, 3, 2));
    const double error = std::abs(noisy.camera.PointInCamera(bridge).z() -
                                  noisy.camera.PointInCamera(noisy.truth[f][3]).z());
    if (error <= 2 * sigma) ++within;
  }
  EXPECT_GE(within, 28);
}

TEST(LiftOneView, AveragesTheInstrumentsOrientationOverTheFramesAround) {
  // Two pixels of noise on every instrument point: each frame's own PnP turns the
  // strings' plane about the strings by a degree or more (the nut and the bridge are 24
  // and 48 mm wide); the held instrument's average over the frames around does not.
  World w = MakeWorld(31, /*sway=*/false);
  AddInstrumentNoise(2.0, /*seed=*/7, &w);
  auto median_error_deg = [&](int window) {
    MonocularLiftOptions o;
    o.rotation_window_frames = window;
    const StatusOr<MonocularLift> lift = LiftOneView(w.camera, w.keypoints, w.scene, o);
    EXPECT_TRUE(lift.ok());
    std::vector<double> degrees;
    for (int f = 0; f < 31; ++f) {
      if (!lift->world_from_instrument[f]) continue;
      degrees.push_back(lift->world_from_instrument[f]->rotation.angularDistance(
                            w.world_from_instrument[f].rotation) *
                        180 / M_PI);
    }
    EXPECT_EQ(degrees.size(), 31u);
    std::nth_element(degrees.begin(), degrees.begin() + 15, degrees.end());
    return degrees[15];
  };
  const double own = median_error_deg(0), averaged = median_error_deg(15);
  EXPECT_GT(own, 1.0);
  EXPECT_LT(averaged, 0.5 * own);
}

TEST(LiftOneView, LiftsNothingInAFrameWithTooFewInstrumentPoints) {
  World w = MakeWorld(4);
  for (int p = 0; p < 4; ++p) w.keypoints.at(2, 0, p, 2) = 0.1;  // 3 points left
  const StatusOr<MonocularLift> lift = LiftOneView(w.camera, w.keypoints, w.scene, {});
  ASSERT_TRUE(lift.ok());
  EXPECT_EQ(lift->summary.frames_with_pose, 3);
  EXPECT_FALSE(lift->world_from_instrument[2].has_value());
  for (int p = 0; p < kPoints; ++p) EXPECT_EQ(lift->depth_source.at(2, p), 0);
}

TEST(LiftOneView, RejectsBadOptionsShapesAndScenes) {
  World w = MakeWorld(2);
  MonocularLiftOptions o;
  o.min_instrument_points = 3;
  EXPECT_NE(LiftOneView(w.camera, w.keypoints, w.scene, o)
                .status()
                .message()
                .find("min_instrument_points"),
            std::string::npos);
  o = {};
  o.depth_window_frames = -1;
  EXPECT_FALSE(LiftOneView(w.camera, w.keypoints, w.scene, o).ok());
  NpyArray<double> two_views = w.keypoints;
  two_views.shape = {1, 2, kPoints, 3};
  EXPECT_FALSE(LiftOneView(w.camera, two_views, w.scene, {}).ok());
  MonocularScene bad = w.scene;
  bad.string_line_depth_columns.push_back(kPoints);
  EXPECT_FALSE(LiftOneView(w.camera, w.keypoints, bad, {}).ok());
  bad = w.scene;
  bad.strings_mm.clear();
  EXPECT_FALSE(LiftOneView(w.camera, w.keypoints, bad, {}).ok());
  o = {};
  o.rotation_window_frames = 301;
  EXPECT_FALSE(LiftOneView(w.camera, w.keypoints, w.scene, o).ok());
}

}  // namespace
}  // namespace arco::track
