// `arco track` on real image content with exact truth (issue 13's moving-plane test): the
// real photo of a cellist (../shared/data/spd/example.jpg) with its labelled cello points
// (example.json) on a flat rectangle of its physical size moves rigidly in front of 6
// calibrated cameras with lens distortion (testing/plane_scene.h renders every view exactly
// into FFV1 videos). Labels are given on the first frame in two views (the labelled
// texture points projected exactly, written as labelme files); `capture new` -> `track`
// -> `triangulate`; every instrument point in every view and frame is compared with its
// exact projection, and its triangulation with its exact 3D position. Side by side, the
// obvious baseline: each view on its own, the labelled points tracked by the same
// Lucas-Kanade with no rigid model (labels given in every view). Figures are printed for
// docs/track.md; the bounds are the issue's.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "arco/capture/capture_new.h"
#include "arco/capture/track_stage.h"
#include "arco/media/video_reader.h"
#include "arco/mocap/capture.h"
#include "arco/mocap/labelme.h"
#include "arco/mocap/triangulate_point.h"
#include "arco/pipeline/triangulate_stage.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/testing/plane_scene.h"
#include "arco/testing/temp_dir.h"
#include "arco/track/instrument_tracker.h"
#include "arco/util/file_io.h"
#include "arco/util/json_io.h"
#include "arco/util/npy.h"
#include "arco/util/stats.h"

namespace arco::capture {
namespace {

namespace fs = std::filesystem;

constexpr double kPhotoMmPerPx = 0.778;  // as detect_plane_test.cc
constexpr int kCameras = 6;
constexpr int kFrames = 45;
constexpr int kLabelViews[2] = {1, 4};

struct Scene {
  arco::testing::TempDir dir{"TrackPlane"};  // the whole suite's folder (made before any test runs)
  testing::PlaneScene scene;
  std::vector<std::string> names;               // the cello's points, layout order
  std::vector<Eigen::Vector2d> bow_texture_px;  // frog, tip
  std::vector<Eigen::Vector2d> texture_px;      // their labelled texture pixels
  std::string capture;
  std::string scene_dir;
  std::string fresh_manifest;  // capture.json as `capture new` wrote it
  double render_s = 0;
};

Scene* g_scene = nullptr;

std::string LabelFile(const std::string& camera, int frame) {
  return camera + "_" + std::to_string(frame + 1) + ".json";
}

std::string LabelmeText(const Camera& cam,
                        const std::vector<std::string>& names,
                        const std::vector<Eigen::Vector2d>& pixels) {
  Json shapes = Json::array();
  for (size_t i = 0; i < names.size(); ++i) {
    // labelme's corner origin: + 0.5.
    shapes.push_back(
        {{"label", names[i]},
         {"points", Json::array({Json::array({pixels[i].x() + 0.5, pixels[i].y() + 0.5})})},
         {"shape_type", "point"}});
  }
  return Json{{"version", "5.3.1"},
              {"shapes", shapes},
              {"imagePath", cam.name + ".png"},
              {"imageWidth", cam.width},
              {"imageHeight", cam.height}}
      .dump(1);
}

class TrackPlane : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    g_scene = new Scene;
    Scene& s = *g_scene;
    const std::string photo = std::string(ARCO_SHARED_DATA_DIR) + "/spd/example.jpg";
    auto reader = media::VideoReader::Open(photo);
    ASSERT_TRUE(reader.ok()) << reader.status().message();
    auto image = reader->ReadFrame(0);
    ASSERT_TRUE(image.ok());
    s.scene.texture.image = *image;
    s.scene.texture.width_mm = image->width * kPhotoMmPerPx;
    s.scene.texture.height_mm = image->height * kPhotoMmPerPx;
    testing::BuildMipmaps(&s.scene.texture);
    testing::PlaneRigOptions rig;
    rig.cameras = kCameras;
    rig.width = 768;
    rig.height = 886;
    rig.focal_px = 760;
    rig.distance_mm = 2500;
    rig.arc_deg = 100;
    s.scene.rig = testing::MakePlaneRig(rig);
    testing::PlaneMotionOptions motion;
    motion.frames = kFrames;
    motion.max_translation_mm = 150;
    motion.max_rotation_deg = 10;
    s.scene.world_from_plane = testing::MakePlaneMotion(motion);
    const auto start = std::chrono::steady_clock::now();
    testing::PlaneSceneWriteOptions write;
    write.render.supersampling = 1;
    const std::string scene_dir = s.dir / "scene";
    s.scene_dir = scene_dir;
    ASSERT_TRUE(testing::WritePlaneScene(s.scene, scene_dir, write).ok());
    s.render_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    // The labelled cello points of the photo.
    auto labels = ReadLabelme(std::string(ARCO_SHARED_DATA_DIR) + "/spd/example.json");
    ASSERT_TRUE(labels.ok()) << labels.status().message();
    const KeypointLayout* layout = FindKeypointLayout("spd_cello");
    for (int slot : *layout->Group("instrument")) {
      const std::string& name = layout->names[slot];
      const int i = labels->Find(name);
      ASSERT_GE(i, 0) << name;
      s.names.push_back(name);
      s.texture_px.push_back(labels->points[i].pixel);
    }
    // Labels on frame 1 in two views, with the bow's (ignored, no warning); on frame 21
    // in the same views and on frame 41 in a third (the middle-frame test).
    for (const auto& [v, f] : std::vector<std::pair<int, int>>{{kLabelViews[0], 0},
                                                               {kLabelViews[1], 0},
                                                               {kLabelViews[0], 20},
                                                               {kLabelViews[1], 20},
                                                               {2, 40}}) {
      const Camera& cam = s.scene.rig.cameras[v];
      std::vector<std::string> names = s.names;
      std::vector<Eigen::Vector2d> px;
      for (const auto& t : s.texture_px) {
        const auto p =
            testing::ProjectPlanePoint(cam, s.scene.world_from_plane[f], s.scene.texture, t);
        ASSERT_TRUE(p && testing::InImage(cam, *p)) << cam.name << " frame " << f;
        px.push_back(*p);
      }
      for (const char* bow : {"frog", "tip_plate"}) {
        const int i = labels->Find(bow);
        ASSERT_GE(i, 0);
        names.push_back(bow);
        if (v == kLabelViews[0] && f == 0) s.bow_texture_px.push_back(labels->points[i].pixel);
        px.push_back(*testing::ProjectPlanePoint(
            cam, s.scene.world_from_plane[f], s.scene.texture, labels->points[i].pixel));
      }
      ASSERT_TRUE(
          AtomicWriteFile(s.dir / LabelFile(cam.name, f), LabelmeText(cam, names, px)).ok());
    }
    CaptureNewOptions c;
    c.calibration = scene_dir + "/calibration.json";
    c.instrument = "cello";
    for (const Camera& cam : s.scene.rig.cameras) {
      c.inputs.push_back({cam.name, scene_dir + "/videos/" + cam.name + ".mkv", false});
    }
    c.output_dir = s.dir / "capture";
    s.capture = c.output_dir;
    auto made = CreateCapture(c);
    ASSERT_TRUE(made.ok()) << made.status().message();
    auto manifest = ReadFileToString(s.capture + "/capture.json");
    ASSERT_TRUE(manifest.ok());
    s.fresh_manifest = *manifest;
  }
  static void TearDownTestSuite() {
    delete g_scene;
    g_scene = nullptr;
  }

  static TrackStageOptions Options(int threads) {
    TrackStageOptions o;
    o.capture_dir = g_scene->capture;
    for (int v : kLabelViews) {
      const std::string cam = g_scene->scene.rig.cameras[v].name;
      o.labels.push_back({cam, -1, g_scene->dir / LabelFile(cam, 0)});
    }
    o.num_threads = threads;
    o.track_bow = true;  // the bow lies on the picture here
    return o;
  }
};

// Every instrument point of keypoints2d.npy against its exact projection: errors (px) of
// the points whose truth is in the image, and per point the frames x views it misses.
void Compare2d(std::vector<double>* errors_px, std::vector<int>* missing) {
  const Scene& s = *g_scene;
  auto kp = ReadNpy<float>(s.capture + "/keypoints2d.npy");
  ASSERT_TRUE(kp.ok()) << kp.status().message();
  const KeypointLayout* layout = FindKeypointLayout("spd_cello");
  ASSERT_EQ(kp->shape[0], kFrames);
  ASSERT_EQ(kp->shape[1], kCameras);
  const int64_t points = kp->shape[2];
  const std::vector<int>& slots = *layout->Group("instrument");
  missing->assign(slots.size(), 0);
  for (int f = 0; f < kFrames; ++f)
    for (int v = 0; v < kCameras; ++v)
      for (size_t p = 0; p < slots.size(); ++p) {
        const float* x =
            &kp->data[static_cast<size_t>(((f * kCameras + v) * points + slots[p]) * 3)];
        const auto truth = testing::ProjectPlanePoint(
            s.scene.rig.cameras[v], s.scene.world_from_plane[f], s.scene.texture, s.texture_px[p]);
        if (!truth || !testing::InImage(s.scene.rig.cameras[v], *truth)) continue;
        if (!std::isfinite(x[0])) {
          ++(*missing)[p];
          continue;
        }
        errors_px->push_back((Eigen::Vector2d(x[0], x[1]) - *truth).norm());
      }
}

TEST_F(TrackPlane, LabelsOnAMiddleFrameTrackBothWays) {
  // Frame 21 in two views (backwards to 1, forwards to 45) and frame 41 in a third view.
  TrackStageOptions o;
  o.capture_dir = g_scene->capture;
  const auto& cams = g_scene->scene.rig.cameras;
  o.labels.push_back(
      {cams[kLabelViews[0]].name, -1, g_scene->dir / LabelFile(cams[kLabelViews[0]].name, 20)});
  o.labels.push_back(
      {cams[kLabelViews[1]].name, -1, g_scene->dir / LabelFile(cams[kLabelViews[1]].name, 20)});
  o.labels.push_back({cams[2].name, 41, g_scene->dir / LabelFile(cams[2].name, 40)});
  o.labels_frame = 21;
  o.num_threads = 2;
  auto tracked = RunTrackStage(o);
  ASSERT_TRUE(tracked.ok()) << tracked.status().message();
  EXPECT_EQ(tracked->template_frame, 21);
  EXPECT_EQ(tracked->frames_without_pose, 0);
  std::vector<double> errors_px;
  std::vector<int> missing;
  Compare2d(&errors_px, &missing);
  ASSERT_FALSE(errors_px.empty());
  std::printf("labels on frame 21 (+ frame 41 in a third view): 2D median %.2f px, 95th %.2f px\n",
              Median(errors_px),
              InterpolatedQuantile(errors_px, 0.95));
  EXPECT_LE(Median(errors_px), 2.0);
  EXPECT_LE(InterpolatedQuantile(errors_px, 0.95), 6.0);
  for (int m : missing) EXPECT_LE(m, 0.02 * kFrames * kCameras);
}

TEST_F(TrackPlane, EveryInstrumentPointInEveryViewAndFrame) {
  Scene& s = *g_scene;
  const auto start = std::chrono::steady_clock::now();
  auto tracked = RunTrackStage(Options(2));
  ASSERT_TRUE(tracked.ok()) << tracked.status().message();
  const double track_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(tracked->warnings.empty()) << (tracked->warnings.empty() ? "" : tracked->warnings[0]);
  EXPECT_TRUE(tracked->bow_tracked);
  std::vector<double> errors_px;
  std::vector<int> missing;
  Compare2d(&errors_px, &missing);
  auto kp = ReadNpy<float>(s.capture + "/keypoints2d.npy");
  ASSERT_TRUE(kp.ok());
  const std::vector<int>& slots = *FindKeypointLayout("spd_cello")->Group("instrument");
  // The body slots stay NaN (no `arco detect`).
  EXPECT_TRUE(std::isnan(kp->data[0]));

  // 3D after `arco triangulate`.
  pipeline::TriangulateStageOptions t;
  t.capture_dir = s.capture;
  t.result_dir = s.dir / "result";
  auto triangulated = pipeline::RunTriangulateStage(t);
  ASSERT_TRUE(triangulated.ok()) << triangulated.status().message();
  auto p3 = ReadNpy<double>(t.result_dir + "/triangulation/points3d_raw.npy");
  ASSERT_TRUE(p3.ok()) << p3.status().message();
  std::vector<double> errors_mm;
  int missing_3d = 0;
  for (int f = 0; f < kFrames; ++f)
    for (size_t p = 0; p < slots.size(); ++p) {
      const double* x = &p3->data[static_cast<size_t>((f * p3->shape[1] + slots[p]) * 3)];
      const Eigen::Vector3d truth =
          testing::PlaneToWorld(s.scene.world_from_plane[f],
                                testing::TexturePixelToPlane(s.scene.texture, s.texture_px[p]));
      if (!std::isfinite(x[0])) {
        ++missing_3d;
        continue;
      }
      errors_mm.push_back((Eigen::Vector3d(x[0], x[1], x[2]) - truth).norm());
    }

  // The baseline: each view alone, the labelled points themselves tracked by Lucas-Kanade.
  std::vector<double> base_px, base_mm;
  int base_missing = 0, base_total = 0;
  {
    std::vector<std::vector<std::vector<Eigen::Vector2d>>> pixels(
        kFrames, std::vector<std::vector<Eigen::Vector2d>>(kCameras));
    for (int v = 0; v < kCameras; ++v) {
      const Camera& cam = s.scene.rig.cameras[v];
      media::VideoReaderOptions ro;
      ro.format = media::PixelFormat::kGray8;
      auto video = media::VideoReader::Open(s.scene_dir + "/videos/" + cam.name + ".mkv", ro);
      ASSERT_TRUE(video.ok());
      std::vector<Eigen::Vector2d> start;
      for (const auto& tp : s.texture_px) {
        start.push_back(
            *testing::ProjectPlanePoint(cam, s.scene.world_from_plane[0], s.scene.texture, tp));
      }
      track::PointTracker2d baseline(track::InstrumentTrackerOptions(), start);
      media::Image previous, current;
      ASSERT_TRUE(video->Read(&previous).ok());
      pixels[0][v] = start;
      for (int f = 1; f < kFrames; ++f) {
        ASSERT_TRUE(*video->Read(&current));
        pixels[f][v] = baseline.Next(previous, current);
        std::swap(previous, current);
      }
    }
    TriangulationOptions to;
    const Triangulator triangulator(s.scene.rig, to);
    for (int f = 0; f < kFrames; ++f)
      for (size_t p = 0; p < slots.size(); ++p) {
        std::vector<PointObservation> obs;
        for (int v = 0; v < kCameras; ++v) {
          const Camera& cam = s.scene.rig.cameras[v];
          const auto truth = testing::ProjectPlanePoint(
              cam, s.scene.world_from_plane[f], s.scene.texture, s.texture_px[p]);
          if (!truth || !testing::InImage(cam, *truth)) continue;
          ++base_total;
          const Eigen::Vector2d& q = pixels[f][v][p];
          if (!std::isfinite(q.x())) {
            ++base_missing;
            continue;
          }
          base_px.push_back((q - *truth).norm());
          obs.push_back({v, q, 1.0});
        }
        const auto x = triangulator.Triangulate(obs);
        if (!x) continue;
        const Eigen::Vector3d truth =
            testing::PlaneToWorld(s.scene.world_from_plane[f],
                                  testing::TexturePixelToPlane(s.scene.texture, s.texture_px[p]));
        base_mm.push_back((x->point_in_world - truth).norm());
      }
  }

  int view_frames = kFrames * kCameras;
  std::printf(
      "scene: %d views x %d frames rendered in %.1f s; tracked in %.1f s (%.1f ms per "
      "view-frame with decoding, %.1f ms without)\n",
      kCameras,
      kFrames,
      s.render_s,
      track_s,
      1e3 * track_s / view_frames,
      1e3 * (tracked->track_s - tracked->decode_s) / view_frames);
  std::printf("| method | 2D median px | 2D 95th px | 3D median mm | 3D 95th mm | missing |\n");
  std::printf("| arco track (labels in 2 views) | %.2f | %.2f | %.2f | %.2f | %.1f%% |\n",
              Median(errors_px),
              InterpolatedQuantile(errors_px, 0.95),
              Median(errors_mm),
              InterpolatedQuantile(errors_mm, 0.95),
              100.0 * *std::max_element(missing.begin(), missing.end()) / (kFrames * kCameras));
  std::printf(
      "| baseline: LK per view (labels in all %d views) | %.2f | %.2f | %.2f | %.2f | %.1f%% |\n",
      kCameras,
      base_px.empty() ? NAN : Median(base_px),
      base_px.empty() ? NAN : InterpolatedQuantile(base_px, 0.95),
      base_mm.empty() ? NAN : Median(base_mm),
      base_mm.empty() ? NAN : InterpolatedQuantile(base_mm, 0.95),
      100.0 * base_missing / std::max(1, base_total));
  ASSERT_FALSE(errors_px.empty());
  ASSERT_FALSE(errors_mm.empty());
  EXPECT_LE(Median(errors_px), 2.0);
  EXPECT_LE(InterpolatedQuantile(errors_px, 0.95), 6.0);
  EXPECT_LE(Median(errors_mm), 4.0);
  EXPECT_LE(InterpolatedQuantile(errors_mm, 0.95), 10.0);
  for (size_t p = 0; p < slots.size(); ++p) {
    EXPECT_LE(missing[p], 0.02 * kFrames * kCameras) << s.names[p];
  }
  EXPECT_LE(missing_3d, 0.02 * kFrames * slots.size());
  EXPECT_EQ(tracked->frames_without_pose, 0);

  // The bow (frog, tip) as a thin body of its own: here it lies on the plane (it moves
  // with the picture), the independent bow is issue 13's other test.
  const std::vector<int>& bow_slots = *FindKeypointLayout("spd_cello")->Group("bow");
  std::vector<double> bow_px, bow_mm;
  for (int f = 0; f < kFrames; ++f)
    for (size_t p = 0; p < bow_slots.size(); ++p) {
      for (int v = 0; v < kCameras; ++v) {
        const float* x =
            &kp->data[static_cast<size_t>(((f * kCameras + v) * kp->shape[2] + bow_slots[p]) * 3)];
        const auto truth = testing::ProjectPlanePoint(s.scene.rig.cameras[v],
                                                      s.scene.world_from_plane[f],
                                                      s.scene.texture,
                                                      s.bow_texture_px[p]);
        if (!truth || !testing::InImage(s.scene.rig.cameras[v], *truth) || !std::isfinite(x[0]))
          continue;
        bow_px.push_back((Eigen::Vector2d(x[0], x[1]) - *truth).norm());
      }
      const double* x = &p3->data[static_cast<size_t>((f * p3->shape[1] + bow_slots[p]) * 3)];
      if (!std::isfinite(x[0])) continue;
      const Eigen::Vector3d truth =
          testing::PlaneToWorld(s.scene.world_from_plane[f],
                                testing::TexturePixelToPlane(s.scene.texture, s.bow_texture_px[p]));
      bow_mm.push_back((Eigen::Vector3d(x[0], x[1], x[2]) - truth).norm());
    }
  ASSERT_FALSE(bow_px.empty());
  ASSERT_FALSE(bow_mm.empty());
  std::printf("| arco track, bow (frog, tip) | %.2f | %.2f | %.2f | %.2f | %zu of %d 3D |\n",
              Median(bow_px),
              InterpolatedQuantile(bow_px, 0.95),
              Median(bow_mm),
              InterpolatedQuantile(bow_mm, 0.95),
              bow_mm.size(),
              2 * kFrames);
  EXPECT_LE(Median(bow_mm), 8.0);
  EXPECT_GE(bow_mm.size(), static_cast<size_t>(2 * kFrames * 0.98));
}

// One camera (one phone): labels of frame 1 in its one view pose arco's cello model
// (track::PoseTemplateInOneView), and that posed model is what the tracker follows. Here
// the instrument is a photo on a flat board, so the model's 3D shape is not the board's:
// the labels' residual against the posed model, and the wrong depth of the tracked
// features, are what one view costs. Compared with the baseline of the test above for the
// same view (the labelled points tracked by Lucas-Kanade in 2D).
TEST_F(TrackPlane, OneCameraFollowsTheInstrumentWithItsModel) {
  Scene& s = *g_scene;
  const Camera& cam = s.scene.rig.cameras[kLabelViews[0]];
  CaptureNewOptions c;
  c.calibration = s.scene_dir + "/calibration.json";
  c.instrument = "cello";
  c.inputs.push_back({cam.name, s.scene_dir + "/videos/" + cam.name + ".mkv", false});
  c.output_dir = s.dir / "one";
  if (!fs::exists(c.output_dir)) {
    auto made = CreateCapture(c);
    ASSERT_TRUE(made.ok()) << made.status().message();
  }
  TrackStageOptions o;
  o.capture_dir = c.output_dir;
  o.labels.push_back({cam.name, -1, s.dir / LabelFile(cam.name, 0)});
  o.num_threads = 2;
  o.track_bow = true;
  auto tracked = RunTrackStage(o);
  ASSERT_TRUE(tracked.ok()) << tracked.status().message();
  EXPECT_EQ(tracked->frames_without_pose, 0);
  // The bow is not tracked from one view; the end pin has no place in the model a view
  // poses.
  EXPECT_FALSE(tracked->bow_tracked);
  EXPECT_EQ(tracked->untracked_points, std::vector<std::string>{"end_pin"});
  auto kp = ReadNpy<float>(c.output_dir + "/keypoints2d.npy");
  ASSERT_TRUE(kp.ok()) << kp.status().message();
  ASSERT_EQ(kp->shape[1], 1);
  const std::vector<int>& slots = *FindKeypointLayout("spd_cello")->Group("instrument");
  std::vector<double> errors_px, base_px;
  int missing = 0;
  media::VideoReaderOptions ro;
  ro.format = media::PixelFormat::kGray8;
  auto video = media::VideoReader::Open(s.scene_dir + "/videos/" + cam.name + ".mkv", ro);
  ASSERT_TRUE(video.ok());
  std::vector<Eigen::Vector2d> start;
  for (const auto& tp : s.texture_px)
    start.push_back(
        *testing::ProjectPlanePoint(cam, s.scene.world_from_plane[0], s.scene.texture, tp));
  track::PointTracker2d baseline(track::InstrumentTrackerOptions(), start);
  media::Image previous, current;
  ASSERT_TRUE(video->Read(&previous).ok());
  std::vector<Eigen::Vector2d> base = start;
  for (int f = 0; f < kFrames; ++f) {
    if (f > 0) {
      ASSERT_TRUE(*video->Read(&current));
      base = baseline.Next(previous, current);
      std::swap(previous, current);
    }
    for (size_t p = 0; p < slots.size(); ++p) {
      if (s.names[p] == "end_pin") continue;
      const auto truth = testing::ProjectPlanePoint(
          cam, s.scene.world_from_plane[f], s.scene.texture, s.texture_px[p]);
      if (!truth || !testing::InImage(cam, *truth)) continue;
      const float* x = &kp->data[static_cast<size_t>((f * kp->shape[2] + slots[p]) * 3)];
      if (!std::isfinite(x[0])) {
        ++missing;
        continue;
      }
      errors_px.push_back((Eigen::Vector2d(x[0], x[1]) - *truth).norm());
      if (std::isfinite(base[p].x())) base_px.push_back((base[p] - *truth).norm());
    }
  }
  ASSERT_FALSE(errors_px.empty());
  ASSERT_FALSE(base_px.empty());
  std::printf("| arco track, one camera (labels in its view) | %.2f | %.2f | - | - | %d |\n",
              Median(errors_px),
              InterpolatedQuantile(errors_px, 0.95),
              missing);
  std::printf("| baseline: LK in that view | %.2f | %.2f | - | - | |\n",
              Median(base_px),
              InterpolatedQuantile(base_px, 0.95));
  std::printf("labels against the posed model: %.2f px\n", tracked->label_rms_px);
  // Issue 13's bounds, as for several views. Measured 0.79 / 2.87 px (median / 95th): the
  // model's shape against the flat board's (two views' template: 0.02 / 0.07 px; the 2D
  // baseline 0.18 / 0.81 px, which tracks the labelled points themselves).
  EXPECT_EQ(missing, 0);
  EXPECT_LE(Median(errors_px), 2.0);
  EXPECT_LE(InterpolatedQuantile(errors_px, 0.95), 6.0);
}

// Two cameras that started later than the others (phones synced by sound: capture.json's
// cameras[].offset_s), one of them labelled: their videos hold the scene from frame
// 1 + k on, k = 12 (a labelled view) and 5 (with a drift_ppm too). `arco track` must solve each
// frame's pose from the pictures of one moment and leave every camera's points where it saw the
// instrument at the capture's frames, as readers of keypoints2d.npy (and `arco triangulate`) sample
// them. Before, it read frame g of every video as one moment: the labelled view's
// labels were checked against its frame 21 (the scene's 33) and its points were 12
// frames off in time.
TEST_F(TrackPlane, CamerasWithAnOffsetAreTrackedAtTheCapturesFrames) {
  Scene& s = *g_scene;
  constexpr int kShifted[2] = {kLabelViews[1], 0};
  constexpr int kShift[2] = {12, 5};
  constexpr int kCaptureFrames = kFrames - 12;
  const std::string capture = s.dir / "capture_offset";
  fs::remove_all(capture);
  fs::create_directories(capture);
  for (const auto& e : fs::directory_iterator(s.capture)) {
    const std::string name = e.path().filename();
    if (name == "capture.json" || name == "keypoints2d.npy" || name == "track.json") continue;
    if (e.is_regular_file()) fs::copy_file(e.path(), capture + "/" + name);
  }
  auto manifest = ParseJsonLenient(s.fresh_manifest, "capture.json");
  ASSERT_TRUE(manifest.ok());
  (*manifest)["frames"]["count"] = kCaptureFrames;
  // The shifted cameras' videos: the scene from frame 1 + k, one camera per scene folder.
  for (int i = 0; i < 2; ++i) {
    const int v = kShifted[i], k = kShift[i];
    testing::PlaneScene late = s.scene;
    late.rig.cameras = {s.scene.rig.cameras[v]};
    late.world_from_plane.assign(s.scene.world_from_plane.begin() + k,
                                 s.scene.world_from_plane.end());
    testing::PlaneSceneWriteOptions write;
    write.render.supersampling = 1;
    const std::string dir = s.dir / ("scene_late_" + std::to_string(v));
    ASSERT_TRUE(testing::WritePlaneScene(late, dir, write).ok());
    Json& cam = (*manifest)["cameras"][v];
    ASSERT_EQ(cam["name"], s.scene.rig.cameras[v].name);
    cam["video"] = dir + "/videos/" + s.scene.rig.cameras[v].name + ".mkv";
    cam["offset_s"] = k / 30.0;
  }
  // The second one's clock also runs 2000 ppm slow by capture.json (its frames rendered
  // at whole frames: up to 0.06 frame off its stated moments), so that its rows are
  // written between capture frames and read back between rows.
  (*manifest)["cameras"][kShifted[1]]["drift_ppm"] = 2000;
  ASSERT_TRUE(AtomicWriteFile(capture + "/capture.json", manifest->dump(1)).ok());

  // Labels of the capture's frame 21 (the scene's): the late labelled camera's are of
  // its own frame 9.
  TrackStageOptions o;
  o.capture_dir = capture;
  for (int v : kLabelViews) {
    const std::string cam = s.scene.rig.cameras[v].name;
    o.labels.push_back({cam, -1, s.dir / LabelFile(cam, 20)});
  }
  o.labels_frame = 21;
  o.num_threads = 2;
  o.track_bow = false;
  auto tracked = RunTrackStage(o);
  ASSERT_TRUE(tracked.ok()) << tracked.status().message();
  EXPECT_EQ(tracked->template_frame, 21);
  EXPECT_EQ(tracked->frames_without_pose, 0);
  EXPECT_LT(tracked->label_rms_px, 0.1);
  // The late cameras saw 33 - k + 1 ... of the capture's frames: k frames without a picture.
  EXPECT_EQ(tracked->cameras[kShifted[0]].frames, kCaptureFrames - kShift[0]);
  EXPECT_EQ(tracked->cameras[kShifted[1]].frames, kCaptureFrames - kShift[1]);

  // Every instrument point at the capture's frames (as every reader samples the rows)
  // against its exact projection at that moment.
  auto read_manifest = ReadCaptureManifest(capture);
  ASSERT_TRUE(read_manifest.ok());
  auto kp = ReadCaptureKeypoints2d(capture, *read_manifest);
  ASSERT_TRUE(kp.ok()) << kp.status().message();
  const std::vector<int>& slots = *FindKeypointLayout("spd_cello")->Group("instrument");
  std::vector<double> errors_px, late_px;
  int missing = 0, late_missing = 0;
  for (int f = 0; f < kCaptureFrames; ++f)
    for (int v = 0; v < kCameras; ++v) {
      const int i = v == kShifted[0] ? 0 : v == kShifted[1] ? 1 : -1;
      for (size_t p = 0; p < slots.size(); ++p) {
        const double* x = &kp->at(f, v, slots[p], 0);
        if (i >= 0 && f < kShift[i]) {
          EXPECT_TRUE(std::isnan(x[0])) << "the camera had not started: frame " << f + 1;
          continue;
        }
        const auto truth = testing::ProjectPlanePoint(
            s.scene.rig.cameras[v], s.scene.world_from_plane[f], s.scene.texture, s.texture_px[p]);
        if (!truth || !testing::InImage(s.scene.rig.cameras[v], *truth)) continue;
        if (!std::isfinite(x[0])) {
          ++(i >= 0 ? late_missing : missing);
          continue;
        }
        const double e = (Eigen::Vector2d(x[0], x[1]) - *truth).norm();
        (i >= 0 ? late_px : errors_px).push_back(e);
      }
    }
  ASSERT_FALSE(errors_px.empty());
  ASSERT_FALSE(late_px.empty());
  std::printf(
      "two cameras 12 and 5 frames late: 2D median %.2f px, 95th %.2f px (the late ones %.2f px, "
      "%.2f px, max %.2f px)\n",
      Median(errors_px),
      InterpolatedQuantile(errors_px, 0.95),
      Median(late_px),
      InterpolatedQuantile(late_px, 0.95),
      *std::max_element(late_px.begin(), late_px.end()));
  EXPECT_LE(Median(errors_px), 2.0);
  EXPECT_LE(InterpolatedQuantile(errors_px, 0.95), 6.0);
  EXPECT_LE(Median(late_px), 2.0);
  EXPECT_LE(InterpolatedQuantile(late_px, 0.95), 6.0);
  EXPECT_EQ(missing, 0);
  EXPECT_EQ(late_missing, 0);

  // 3D from `arco triangulate` at the capture's frames.
  pipeline::TriangulateStageOptions t;
  t.capture_dir = capture;
  t.result_dir = s.dir / "result_offset";
  auto triangulated = pipeline::RunTriangulateStage(t);
  ASSERT_TRUE(triangulated.ok()) << triangulated.status().message();
  auto p3 = ReadNpy<double>(t.result_dir + "/triangulation/points3d_raw.npy");
  ASSERT_TRUE(p3.ok()) << p3.status().message();
  std::vector<double> errors_mm;
  for (int f = 0; f < kCaptureFrames; ++f)
    for (size_t p = 0; p < slots.size(); ++p) {
      const double* x = &p3->data[static_cast<size_t>((f * p3->shape[1] + slots[p]) * 3)];
      if (!std::isfinite(x[0])) continue;
      const Eigen::Vector3d truth =
          testing::PlaneToWorld(s.scene.world_from_plane[f],
                                testing::TexturePixelToPlane(s.scene.texture, s.texture_px[p]));
      errors_mm.push_back((Eigen::Vector3d(x[0], x[1], x[2]) - truth).norm());
    }
  ASSERT_GE(errors_mm.size(), static_cast<size_t>(0.98 * kCaptureFrames * slots.size()));
  std::printf("  3D median %.2f mm, 95th %.2f mm\n",
              Median(errors_mm),
              InterpolatedQuantile(errors_mm, 0.95));
  EXPECT_LE(Median(errors_mm), 4.0);
  EXPECT_LE(InterpolatedQuantile(errors_mm, 0.95), 10.0);
}

TEST_F(TrackPlane, SameBytesForAnyThreadCount) {
  Scene& s = *g_scene;
  // Each run starts from the capture as `capture new` made it.
  std::vector<std::string> npy, json;
  for (int threads : {1, 2}) {
    ASSERT_TRUE(AtomicWriteFile(s.capture + "/capture.json", s.fresh_manifest).ok());
    fs::remove(s.capture + "/keypoints2d.npy");
    auto run = RunTrackStage(Options(threads));
    ASSERT_TRUE(run.ok()) << run.status().message();
    EXPECT_FALSE(run->kept_other_points);
    npy.push_back(*ReadFileToString(s.capture + "/keypoints2d.npy"));
    json.push_back(*ReadFileToString(s.capture + "/track.json"));
  }
  EXPECT_TRUE(npy[0] == npy[1]);
  EXPECT_TRUE(json[0] == json[1]);
}

}  // namespace
}  // namespace arco::capture
