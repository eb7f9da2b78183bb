// Detector latency (docs/performance.md, section "Detect"), 2 OpenCV threads, wall
// time (OpenCV's pool threads do the work, not the calling thread: real time):
// - BM_Inference/MODEL/THREADS: one forward pass of each converted MediaPipe model
//   (detect::Network::Run: NHWC -> NCHW copy, forward, outputs copied out) on a fixed
//   pseudo-random input of the model's size (the time does not depend on the content),
//   on 2 OpenCV threads and on 1 (as each worker of `arco detect` runs);
// - BM_WholeBodyTracked / BM_WholeBodyDetected: detect::WholeBodyTracker::Track per
//   view-frame on the real SPD cellist (2300 x 2656): a tracked frame (pose landmarks in
//   the carried ROI, hand_recrop and hand landmarks for both hands) and a frame that
//   starts with the person detector (after Reset). Counters split the time per frame:
//   inference_ms (forward passes only, the 45 ms target), per model, and
//   preprocess_ms (cutting and converting crops) and postprocess_ms (decoding), which
//   the tracker times separately;
// - BM_DecodeFrame: reading frames with media::VideoReader (decoding is not part of
//   the tracker's time): opencv-doc's vtest.avi (768 x 576 MPEG-4) and the cellist JPEG;
// - BM_DetectStagePlane: `arco detect` (capture::RunDetectStage, default models) on
//   capture_detect_plane_test's scene (8 views x 12 frames of 1152 x 1328, rendered
//   once per codec, untimed), wall time per view-frame with decoding, for --threads 1
//   and 2, with frames decoded ahead on a thread beside each worker or in turn (issue
//   28), and with the videos as lossless FFV1 RGB (the tests' codec) or as H.264 at
//   high quality (libx264 crf 16, yuv420p: what phones and cameras deliver). With
//   ARCO_DETECT_BENCH_DIR set the captures are made there and kept (FOLDER/ffv1/capture,
//   FOLDER/h264/capture), e.g. to run `arco detect` of two builds on the same videos.
#include <benchmark/benchmark.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "arco/capture/capture_new.h"
#include "arco/capture/detect_stage.h"
#include "arco/detect/network.h"
#include "arco/detect/wholebody.h"
#include "arco/media/video_reader.h"
#include "arco/media/video_writer.h"
#include "arco/testing/plane_scene.h"

namespace arco::detect {
namespace {

void BM_Inference(benchmark::State& state) {
  const ModelInfo& info = AllModels()[state.range(0)];
  state.SetLabel(std::string(info.name) + ", " + std::to_string(state.range(1)) + " thread(s)");
  NetworkOptions options;
  options.num_threads = static_cast<int>(state.range(1));
  StatusOr<Network> network = Network::Load(info.id, DefaultModelsDir(), options);
  if (!network.ok()) {
    state.SkipWithError(network.status().message().c_str());
    return;
  }
  std::vector<float> input(3 * static_cast<size_t>(info.input_width) * info.input_height);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  for (float& v : input) v = uniform(rng);
  if (!network->Run(input.data(), input.size()).ok()) {  // warm-up: first pass allocates
    state.SkipWithError("inference failed");
    return;
  }
  for (auto _ : state) {
    Status status = network->Run(input.data(), input.size());
    benchmark::DoNotOptimize(status);
  }
}
BENCHMARK(BM_Inference)
    ->ArgsProduct({benchmark::CreateDenseRange(0, 7, 1), {2, 1}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

const char* const kCellist = ARCO_SHARED_DATA_DIR "/spd/example.jpg";
const char* const kVtest = "/usr/share/doc/opencv-doc/examples/data/vtest.avi";

// Per-frame counters from the tracker's summary between two points.
void ReportPerFrame(benchmark::State& state,
                    const WholeBodySummary& before,
                    const WholeBodySummary& after) {
  const double frames = static_cast<double>(after.frames - before.frames);
  if (frames <= 0) return;
  auto per_frame_ms = [&](double seconds) { return 1e3 * seconds / frames; };
  state.counters["inference_ms"] = per_frame_ms(after.inference_s - before.inference_s);
  state.counters["preprocess_ms"] = per_frame_ms(after.preprocess_s - before.preprocess_s);
  state.counters["postprocess_ms"] = per_frame_ms(after.postprocess_s - before.postprocess_s);
  const char* names[] = {"detector_ms", "pose_ms", "recrop_ms", "hands_ms"};
  for (size_t k = 0; k < after.models.size(); ++k) {
    state.counters[names[k]] =
        per_frame_ms(after.models[k].inference_s - before.models[k].inference_s);
  }
}

// range(0): pose model 0 lite, 1 full, 2 heavy; range(1): hand model 0 lite, 1 full.
void WholeBody(benchmark::State& state, bool detect_every_frame) {
  const PoseModel model = static_cast<PoseModel>(state.range(0));
  const HandModel hands = static_cast<HandModel>(state.range(1));
  state.SetLabel(std::string("pose ") + PoseModelName(model) + ", hands " +
                 HandModelName(hands) + ", recrop");
  StatusOr<media::VideoReader> reader = media::VideoReader::Open(kCellist);
  if (!reader.ok()) {
    state.SkipWithError(reader.status().message().c_str());
    return;
  }
  StatusOr<media::Image> image = reader->ReadFrame(0);
  WholeBodyOptions options;
  options.pose_model = model;
  options.hand_model = hands;
  options.num_threads = 2;
  StatusOr<WholeBodyTracker> tracker = WholeBodyTracker::Create(options);
  if (!image.ok() || !tracker.ok()) {
    state.SkipWithError(tracker.ok() ? "cannot read the image"
                                     : tracker.status().message().c_str());
    return;
  }
  // Warm-up (first passes allocate) and, for tracked frames, the first detection.
  for (int i = 0; i < 2; ++i) {
    if (!tracker->Track(*image).ok()) {
      state.SkipWithError("inference failed");
      return;
    }
  }
  const WholeBodySummary before = tracker->summary();
  for (auto _ : state) {
    if (detect_every_frame) tracker->Reset();
    StatusOr<WholeBodyFrame> out = tracker->Track(*image);
    benchmark::DoNotOptimize(out);
  }
  ReportPerFrame(state, before, tracker->summary());
}
void BM_WholeBodyTracked(benchmark::State& state) { WholeBody(state, false); }
void BM_WholeBodyDetected(benchmark::State& state) { WholeBody(state, true); }
BENCHMARK(BM_WholeBodyTracked)
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WholeBodyDetected)->Args({1, 1})->UseRealTime()->Unit(benchmark::kMillisecond);

// range(0): 0 vtest.avi read sequentially (rewinding at the end), 1 the cellist JPEG.
void BM_DecodeFrame(benchmark::State& state) {
  const char* path = state.range(0) == 0 ? kVtest : kCellist;
  state.SetLabel(state.range(0) == 0 ? "vtest.avi 768x576 mpeg4" : "example.jpg 2300x2656");
  StatusOr<media::VideoReader> reader = media::VideoReader::Open(path);
  if (!reader.ok()) {
    state.SkipWithError(reader.status().message().c_str());
    return;
  }
  media::Image frame;
  const int64_t frame_count = reader->properties().frame_count;
  for (auto _ : state) {
    if (reader->next_frame() >= frame_count) {  // rewind, untimed
      state.PauseTiming();
      const Status seek = reader->Seek(0);
      state.ResumeTiming();
      if (!seek.ok()) {
        state.SkipWithError(seek.message().c_str());
        return;
      }
    }
    StatusOr<bool> more = reader->Read(&frame);
    if (!more.ok() || !*more) {
      state.SkipWithError("read failed");
      return;
    }
  }
}
BENCHMARK(BM_DecodeFrame)->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond);

// capture_detect_plane_test's capture (same photo, rig and motion), made once per
// process in a temporary folder removed at exit; empty with the reason on failure.
struct PlaneCapture {
  std::string dir, error;
  int64_t view_frames = 0;
  bool keep = false;
  ~PlaneCapture() {
    if (!dir.empty() && !keep) std::filesystem::remove_all(dir);
  }
};
// codec 0: FFV1 (lossless RGB), 1: libx264 (crf 16, yuv420p).
const PlaneCapture& GetPlaneCapture(int codec) {
  static PlaneCapture captures[2];
  static bool tried[2] = {false, false};
  PlaneCapture& c = captures[codec];
  if (tried[codec]) return c;
  tried[codec] = true;
  {
    const char* keep_dir = std::getenv("ARCO_DETECT_BENCH_DIR");
    if (keep_dir != nullptr && *keep_dir != '\0') {
      c.dir = std::string(keep_dir) + (codec == 0 ? "/ffv1" : "/h264");
      c.keep = true;
      std::filesystem::remove_all(c.dir);
      std::filesystem::create_directories(c.dir);
    } else {
      char pattern[] = "/tmp/arco_detect_bench_XXXXXX";
      if (mkdtemp(pattern) == nullptr) {
        c.error = "cannot make a temporary folder";
        return c;
      }
      c.dir = pattern;
    }
    StatusOr<media::VideoReader> reader = media::VideoReader::Open(kCellist);
    if (!reader.ok()) {
      c.error = reader.status().message();
      return c;
    }
    StatusOr<media::Image> image = reader->ReadFrame(0);
    if (!image.ok()) {
      c.error = image.status().message();
      return c;
    }
    const testing::PlaneScene scene = testing::DetectPlaneScene(*image);
    testing::PlaneSceneWriteOptions write;
    write.render.supersampling = 1;
    if (codec == 1) {
      if (!media::HasVideoEncoder("libx264")) {
        c.error = "this FFmpeg has no libx264 encoder";
        return c;
      }
      write.codec = "libx264";
    }
    const std::string scene_dir = c.dir + "/scene";
    const Status written = testing::WritePlaneScene(scene, scene_dir, write);
    if (!written.ok()) {
      c.error = written.message();
      return c;
    }
    capture::CaptureNewOptions o;
    o.calibration = scene_dir + "/calibration.json";
    for (const Camera& cam : scene.rig.cameras) {
      o.inputs.push_back({cam.name, scene_dir + "/videos/" + cam.name + ".mkv", false});
    }
    o.output_dir = c.dir + "/capture";
    auto made = capture::CreateCapture(o);
    if (!made.ok()) {
      c.error = made.status().message();
      return c;
    }
    c.view_frames =
        static_cast<int64_t>(scene.rig.cameras.size() * scene.world_from_plane.size());
  }
  return c;
}

// range(0): --threads; range(1): 1 decode ahead, 0 decode and track in turn; range(2):
// 0 FFV1 videos, 1 H.264.
void BM_DetectStagePlane(benchmark::State& state) {
  const PlaneCapture& capture = GetPlaneCapture(static_cast<int>(state.range(2)));
  if (!capture.error.empty()) {
    state.SkipWithError(capture.error.c_str());
    return;
  }
  capture::DetectStageOptions o;
  o.capture_dir = capture.dir + "/capture";
  o.num_threads = static_cast<int>(state.range(0));
  o.decode_ahead = state.range(1) != 0;
  state.SetLabel(std::string(state.range(2) == 0 ? "FFV1, " : "H.264, ") +
                 (o.decode_ahead ? "decode ahead" : "decode in turn") + ", " +
                 std::to_string(o.num_threads) + " threads");
  double decode_s = 0, wait_s = 0, inference_s = 0;
  std::array<double, 4> model_s{};
  int64_t runs = 0;
  for (auto _ : state) {
    StatusOr<capture::DetectStageSummary> s = capture::RunDetectStage(o);
    if (!s.ok()) {
      state.SkipWithError(s.status().message().c_str());
      return;
    }
    decode_s += s->decode_s;
    wait_s += s->decode_wait_s;
    inference_s += s->total.inference_s;
    for (size_t k = 0; k < model_s.size(); ++k) model_s[k] += s->total.models[k].inference_s;
    ++runs;
  }
  // Per view-frame: the wall time is the benchmark's own (Time / view_frames); the
  // counters are summed over workers.
  const double per_view_frame = 1e3 / static_cast<double>(runs * capture.view_frames);
  state.counters["view_frames"] = static_cast<double>(capture.view_frames);
  state.counters["decode_ms"] = decode_s * per_view_frame;
  state.counters["decode_wait_ms"] = wait_s * per_view_frame;
  state.counters["inference_ms"] = inference_s * per_view_frame;
  const char* names[] = {"detector_ms", "pose_ms", "recrop_ms", "hands_ms"};
  for (size_t k = 0; k < model_s.size(); ++k)
    state.counters[names[k]] = model_s[k] * per_view_frame;
}
BENCHMARK(BM_DetectStagePlane)
    ->ArgsProduct({{1, 2}, {0, 1}, {0, 1}})
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace arco::detect
BENCHMARK_MAIN();
