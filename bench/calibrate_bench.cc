// `arco calibrate` on the synthetic ring (calibration/synthetic_board_rig.h): 8 distorted
// 1920x1080 cameras on a 3 m ring, a 9x6 chessboard (80 mm squares) in 300 frames, each
// frame seen by the 2-4 cameras it faces (docs/performance.md).
//   BM_DetectBoardFrame/board and /empty: one frame's detection (findChessboardCorners on
//     the frame scaled to 1280 px, cornerSubPix at full size), on rendered frames.
//   BM_CalibrateRig: intrinsics, initial poses and the bundle adjustment over the 8 x 300
//     frames' detections (exact corners + 0.1 px noise); one thread (OpenCV's own loops
//     aside).
// Detection of the whole rig = views x board + (2400 - views) x empty, over the threads.
#include <benchmark/benchmark.h>

#include "arco/calibration/board_detection.h"
#include "arco/calibration/rig_calibration.h"
#include "arco/testing/synthetic_board_rig.h"

namespace arco::calibration {
namespace {

struct Scene {
  BoardSpec board;
  testing::SyntheticBoardRig rig;
  std::vector<media::Image> board_frames;  // a sample of camera 0's views, rendered
  media::Image empty;
};

const Scene& GetScene() {
  static const Scene* scene = [] {
    auto* s = new Scene;
    s->board.inner_cols = 9;
    s->board.inner_rows = 6;
    s->board.square_mm = 80;
    testing::SyntheticBoardRigOptions options;
    options.num_frames = 300;
    s->rig = testing::MakeSyntheticBoardRig(s->board, options);
    const testing::BoardRenderer renderer(s->board, s->rig.truth.cameras[0], 2);
    for (size_t i = 0; i < s->rig.views[0].views.size() && i < 24; ++i)
      s->board_frames.push_back(
          renderer.Render(s->rig.world_from_board[s->rig.views[0].views[i].frame]));
    s->empty = renderer.Render(Eigen::Isometry3d(Eigen::Translation3d(0, 0, -1e5)));
    return s;
  }();
  return *scene;
}

void BM_DetectBoardFrame_board(benchmark::State& state) {
  const Scene& s = GetScene();
  size_t i = 0, found = 0, tried = 0;
  for (auto _ : state) {
    const auto view = DetectBoard(s.board, s.board_frames[i++ % s.board_frames.size()]);
    found += view.has_value();
    ++tried;
    benchmark::DoNotOptimize(view);
  }
  state.counters["found"] = static_cast<double>(found) / tried;
}
BENCHMARK(BM_DetectBoardFrame_board)->Unit(benchmark::kMillisecond);

void BM_DetectBoardFrame_empty(benchmark::State& state) {
  const Scene& s = GetScene();
  for (auto _ : state) benchmark::DoNotOptimize(DetectBoard(s.board, s.empty));
}
BENCHMARK(BM_DetectBoardFrame_empty)->Unit(benchmark::kMillisecond);

void BM_CalibrateRig(benchmark::State& state) {
  const Scene& s = GetScene();
  RigCalibrationOptions options;
  int views = 0;
  for (const auto& c : s.rig.views) views += static_cast<int>(c.views.size());
  double ba_s = 0, rms = 0;
  int iterations = 0;
  for (auto _ : state) {
    auto result = CalibrateRig(options, s.board, s.rig.views);
    if (!result.ok()) {
      state.SkipWithError(result.status().message().c_str());
      return;
    }
    ba_s = result->report.bundle_adjustment.time_s;
    iterations = result->report.bundle_adjustment.iterations;
    rms = result->report.rms_px;
  }
  state.counters["views"] = views;
  state.counters["ba_s"] = ba_s;
  state.counters["ba_iterations"] = iterations;
  state.counters["rms_px"] = rms;
}
BENCHMARK(BM_CalibrateRig)->Unit(benchmark::kSecond)->Iterations(2)->MeasureProcessCPUTime();

}  // namespace
}  // namespace arco::calibration
BENCHMARK_MAIN();
