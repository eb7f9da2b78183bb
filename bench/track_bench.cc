// The instrument tracker's cost (docs/performance.md, section "Track"), wall time:
// BM_TrackInstrument/T tracks the moving-plane scene of capture_track_plane_test (the
// real SPD cellist photo on a rigidly moving plane, 6 distorted 768 x 886 views, labels
// on frame 1 in two views) for 20 frames with T threads, frames already decoded and in
// memory (decoding is media::VideoReader's, timed by detect_bench's BM_DecodeFrame).
// Counter ms_per_view_frame: track::InstrumentTracker::Next per view-frame.
// BM_TrackBow/R tracks the moving bow of capture_track_bow_test (a 720 x 24 mm strip of
// random 6 mm blocks, +-200 mm strokes at 0.7 Hz and +-10 degree string crossings, over
// the photo at rest; same rig) for 20 frames on one thread: R = 1 with the all-view pose
// (BowTrackerOptions::refine), R = 0 without. Counter cpu_ms_per_view_frame:
// track::BowTracker::Next's process CPU time per view-frame (the machine may be shared:
// CPU time, not wall).
#include <benchmark/benchmark.h>

#include <chrono>
#include <ctime>
#include <string>
#include <vector>

#include "arco/media/video_reader.h"
#include "arco/mocap/labelme.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/testing/plane_bow.h"
#include "arco/testing/plane_scene.h"
#include "arco/track/bow_tracker.h"
#include "arco/track/instrument_tracker.h"

namespace arco::track {
namespace {

constexpr int kFrames = 20;

struct Scene {
  std::vector<Camera> cameras;
  std::vector<std::vector<media::Image>> frames;  // [frame][view], gray
  RigidTemplate body;
  std::string error;
};

const Scene& GetScene() {
  static const Scene scene = [] {
    Scene s;
    const std::string data = ARCO_SHARED_DATA_DIR;
    auto reader = media::VideoReader::Open(data + "/spd/example.jpg");
    auto labels = ReadLabelme(data + "/spd/example.json");
    if (!reader.ok() || !labels.ok()) {
      s.error = "../shared/data/spd/example.jpg and example.json are needed";
      return s;
    }
    testing::PlaneTexture texture;
    texture.image = *reader->ReadFrame(0);
    texture.width_mm = texture.image.width * 0.778;
    texture.height_mm = texture.image.height * 0.778;
    testing::BuildMipmaps(&texture);
    testing::PlaneRigOptions rig;
    rig.cameras = 6;
    rig.width = 768;
    rig.height = 886;
    rig.focal_px = 760;
    const Rig r = testing::MakePlaneRig(rig);
    s.cameras = r.cameras;
    testing::PlaneMotionOptions motion;
    motion.frames = kFrames;
    motion.max_rotation_deg = 10;
    const std::vector<Rigid3d> poses = testing::MakePlaneMotion(motion);
    testing::PlaneRenderOptions render;
    render.supersampling = 1;
    render.threads = 2;
    s.frames.resize(kFrames);
    for (const Camera& cam : s.cameras) {
      const testing::PlaneRenderer renderer(cam, render);
      const media::Image background =
          testing::MakeSolidImage(cam.width, cam.height, media::PixelFormat::kGray8, {90, 90, 90});
      for (int f = 0; f < kFrames; ++f) {
        media::Image out;
        renderer.Render(poses[f], texture, background, &out);
        s.frames[f].push_back(std::move(out));
      }
    }
    FrameLabels frame_labels;
    const KeypointLayout* layout = FindKeypointLayout("spd_cello");
    frame_labels.pixels.assign(s.cameras.size(), {});
    for (int slot : *layout->Group("instrument")) {
      const std::string& name = layout->names[slot];
      frame_labels.point_names.push_back(name);
      const Eigen::Vector2d t = labels->points[labels->Find(name)].pixel;
      for (size_t v = 0; v < s.cameras.size(); ++v) {
        const bool labelled = v == 1 || v == 4;
        frame_labels.pixels[v].push_back(
            labelled ? *testing::ProjectPlanePoint(s.cameras[v], poses[0], texture, t)
                     : Eigen::Vector2d::Constant(NAN));
      }
    }
    auto body = TriangulateTemplate(s.cameras, frame_labels);
    if (!body.ok()) {
      s.error = body.status().message();
      return s;
    }
    s.body = *body;
    return s;
  }();
  return scene;
}

std::vector<const media::Image*> Pointers(const std::vector<media::Image>& frames) {
  std::vector<const media::Image*> p;
  for (const auto& f : frames) p.push_back(&f);
  return p;
}

void BM_TrackInstrument(benchmark::State& state) {
  const Scene& s = GetScene();
  if (!s.error.empty()) {
    state.SkipWithError(s.error.c_str());
    return;
  }
  InstrumentTrackerOptions options;
  options.num_threads = static_cast<int>(state.range(0));
  double next_s = 0;
  int64_t view_frames = 0;
  for (auto _ : state) {
    InstrumentTracker tracker(s.cameras, s.body, options);
    tracker.Start(Pointers(s.frames[0]));
    const auto start = std::chrono::steady_clock::now();
    for (int f = 1; f < kFrames; ++f) {
      benchmark::DoNotOptimize(tracker.Next(Pointers(s.frames[f])));
    }
    next_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    view_frames += static_cast<int64_t>(kFrames - 1) * s.cameras.size();
  }
  state.counters["ms_per_view_frame"] = 1e3 * next_s / std::max<int64_t>(1, view_frames);
}
BENCHMARK(BM_TrackInstrument)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

struct BowScene {
  std::vector<Camera> cameras;
  std::vector<std::vector<media::Image>> frames;  // [frame][view], gray
  Eigen::Vector3d frog, tip;                      // frame 0's, exact
  std::string error;
};

const BowScene& GetBowScene() {
  static const BowScene scene = [] {
    BowScene s;
    const std::string data = ARCO_SHARED_DATA_DIR;
    auto reader = media::VideoReader::Open(data + "/spd/example.jpg");
    if (!reader.ok()) {
      s.error = "../shared/data/spd/example.jpg is needed";
      return s;
    }
    testing::PlaneTexture cello;
    cello.image = *reader->ReadFrame(0);
    cello.width_mm = cello.image.width * 0.778;
    cello.height_mm = cello.image.height * 0.778;
    testing::BuildMipmaps(&cello);
    const testing::PlaneTexture bow = testing::MakeBowTexture();
    const std::vector<Rigid3d> poses = testing::MakeBowingMotion(kFrames);
    s.frog =
        testing::PlaneToWorld(poses[0], testing::TexturePixelToPlane(bow, testing::kBowFrogPx));
    s.tip = testing::PlaneToWorld(poses[0], testing::TexturePixelToPlane(bow, testing::kBowTipPx));
    testing::PlaneRigOptions rig;
    rig.cameras = 6;
    rig.width = 768;
    rig.height = 886;
    rig.focal_px = 760;
    s.cameras = testing::MakePlaneRig(rig).cameras;
    testing::PlaneRenderOptions render;
    render.supersampling = 1;
    render.threads = 2;
    s.frames.resize(kFrames);
    for (const Camera& cam : s.cameras) {
      const testing::PlaneRenderer renderer(cam, render);
      const media::Image background =
          testing::MakeSolidImage(cam.width, cam.height, media::PixelFormat::kGray8, {90, 90, 90});
      media::Image picture;
      renderer.Render(testing::PlaneRestPose(), cello, background, &picture);
      for (int f = 0; f < kFrames; ++f) {
        media::Image out;
        renderer.Render(poses[f], bow, picture, &out);
        s.frames[f].push_back(std::move(out));
      }
    }
    return s;
  }();
  return scene;
}

void BM_TrackBow(benchmark::State& state) {
  const BowScene& s = GetBowScene();
  if (!s.error.empty()) {
    state.SkipWithError(s.error.c_str());
    return;
  }
  BowTrackerOptions options;
  options.num_threads = 1;
  options.refine = state.range(0) != 0;
  double cpu_s = 0;
  int64_t view_frames = 0;
  for (auto _ : state) {
    BowTracker tracker(s.cameras, s.frog, s.tip, options);
    tracker.Start(Pointers(s.frames[0]));
    const std::clock_t start = std::clock();
    for (int f = 1; f < kFrames; ++f) {
      benchmark::DoNotOptimize(tracker.Next(Pointers(s.frames[f])));
    }
    cpu_s += static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC;
    view_frames += static_cast<int64_t>(kFrames - 1) * s.cameras.size();
  }
  state.counters["cpu_ms_per_view_frame"] = 1e3 * cpu_s / std::max<int64_t>(1, view_frames);
}
BENCHMARK(BM_TrackBow)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace arco::track
BENCHMARK_MAIN();
