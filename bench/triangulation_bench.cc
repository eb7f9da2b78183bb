// Sequence triangulation on a synthetic 20-camera rig (SPD-like: 2300x2656 px,
// distortion), 142 keypoints per frame, 1 px noise, 5% outlier detections (40-400 px
// off, with high scores), 10% missing. Reports points per second for arco
// (TriangulateSequence) and for the SPD authors' exhaustive-pair algorithm
// (exhaustive_pairs.h) on 1 and 2 threads, in the same binary, plus the accuracy of
// both against the truth. BM_SpeedRatio times both on the same frames in each
// iteration and reports baseline_time / arco_time.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "arco/mocap/triangulate_sequence.h"
#include "arco/testing/synthetic_views.h"
#include "arco/util/parallel.h"
#include "exhaustive_pairs.h"

namespace arco::bench {
namespace {

constexpr int kCameras = 20;
constexpr int kPoints = 142;
constexpr int kFrames = 24;

struct Scene {
  Rig rig;
  NpyArray<double> truth, detections;
  std::vector<int> view_to_camera;
  std::vector<Eigen::Matrix<double, 3, 4>> projections;
};

const Scene& GetScene() {
  static const Scene* scene = [] {
    auto* s = new Scene;
    testing::SyntheticRigOptions r;
    r.num_cameras = kCameras;
    s->rig = testing::MakeSyntheticRig(r);
    s->truth = testing::MakeSyntheticPoints(kFrames, kPoints, 3);
    testing::SyntheticDetectionOptions d;
    d.noise_px = 1.0;
    d.outlier_fraction = 0.05;
    d.missing_fraction = 0.1;
    s->detections = testing::MakeSyntheticDetections(s->rig, s->truth, d);
    for (int c = 0; c < kCameras; ++c) {
      s->view_to_camera.push_back(c);
      s->projections.push_back(s->rig.cameras[c].ProjectionMatrix());
    }
    return s;
  }();
  return *scene;
}

NpyArray<double> RunArco(const Scene& s, int threads, bool refine = true) {
  SequenceTriangulationOptions o;
  o.num_threads = threads;
  o.point.refine = refine;
  auto r = TriangulateSequence(s.rig, s.view_to_camera, s.detections, o);
  return std::move(r->points3d);
}

NpyArray<double> RunBaseline(const Scene& s, int threads) {
  NpyArray<double> out;
  out.shape = {kFrames, kPoints, 3};
  out.data.assign(kFrames * kPoints * 3, NAN);
  ParallelFor(
      kFrames,
      threads,
      [&](int64_t f, int) {
        std::vector<Eigen::Vector2d> pixels(kCameras);
        std::vector<double> scores(kCameras);
        for (int p = 0; p < kPoints; ++p) {
          for (int v = 0; v < kCameras; ++v) {
            pixels[v] = {s.detections.at(f, v, p, 0), s.detections.at(f, v, p, 1)};
            const double score = s.detections.at(f, v, p, 2);
            scores[v] = std::isfinite(score) ? score : 0.0;
          }
          const auto x = TriangulateExhaustivePairs(s.projections, pixels, scores);
          if (!x) continue;
          for (int k = 0; k < 3; ++k) out.at(f, p, k) = (*x)[k];
        }
      },
      1);
  return out;
}

// Mean and 99th percentile of the 3D error (mm; the rig is in metres).
void ReportAccuracy(benchmark::State& state, const NpyArray<double>& points) {
  const Scene& s = GetScene();
  std::vector<double> errors;
  for (int64_t i = 0; i < kFrames * kPoints; ++i) {
    const Eigen::Vector3d a(points.data[3 * i], points.data[3 * i + 1], points.data[3 * i + 2]);
    const Eigen::Vector3d b(s.truth.data[3 * i], s.truth.data[3 * i + 1], s.truth.data[3 * i + 2]);
    if (a.allFinite()) errors.push_back(1000.0 * (a - b).norm());
  }
  std::sort(errors.begin(), errors.end());
  double sum = 0;
  for (double e : errors) sum += e;
  state.counters["mean_error_mm"] = errors.empty() ? NAN : sum / errors.size();
  state.counters["p99_error_mm"] = errors.empty() ? NAN : errors[errors.size() * 99 / 100];
  state.counters["triangulated_pct"] = 100.0 * errors.size() / (kFrames * kPoints);
}

void BM_ArcoSequence(benchmark::State& state) {
  const Scene& s = GetScene();
  const int threads = static_cast<int>(state.range(0));
  NpyArray<double> points;
  for (auto _ : state) {
    points = RunArco(s, threads);
    benchmark::DoNotOptimize(points.data.data());
  }
  state.SetItemsProcessed(state.iterations() * kFrames * kPoints);  // points/s
  ReportAccuracy(state, points);
}
BENCHMARK(BM_ArcoSequence)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// What the Levenberg-Marquardt refinement costs and buys (one thread).
void BM_ArcoSequenceNoRefine(benchmark::State& state) {
  const Scene& s = GetScene();
  NpyArray<double> points;
  for (auto _ : state) {
    points = RunArco(s, 1, /*refine=*/false);
    benchmark::DoNotOptimize(points.data.data());
  }
  state.SetItemsProcessed(state.iterations() * kFrames * kPoints);
  ReportAccuracy(state, points);
}
BENCHMARK(BM_ArcoSequenceNoRefine)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ExhaustivePairsBaseline(benchmark::State& state) {
  const Scene& s = GetScene();
  const int threads = static_cast<int>(state.range(0));
  NpyArray<double> points;
  for (auto _ : state) {
    points = RunBaseline(s, threads);
    benchmark::DoNotOptimize(points.data.data());
  }
  state.SetItemsProcessed(state.iterations() * kFrames * kPoints);
  ReportAccuracy(state, points);
}
BENCHMARK(BM_ExhaustivePairsBaseline)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// Both on the same frames, alternating inside each iteration: speedup = baseline / arco.
void BM_SpeedRatio(benchmark::State& state) {
  const Scene& s = GetScene();
  const int threads = static_cast<int>(state.range(0));
  double arco_s = 0, baseline_s = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    auto a = RunArco(s, threads);
    const auto t1 = std::chrono::steady_clock::now();
    auto b = RunBaseline(s, threads);
    const auto t2 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(a.data.data());
    benchmark::DoNotOptimize(b.data.data());
    arco_s += std::chrono::duration<double>(t1 - t0).count();
    baseline_s += std::chrono::duration<double>(t2 - t1).count();
  }
  const double points = static_cast<double>(state.iterations()) * kFrames * kPoints;
  state.counters["arco_points_per_s"] = points / arco_s;
  state.counters["baseline_points_per_s"] = points / baseline_s;
  state.counters["speedup"] = baseline_s / arco_s;
}
BENCHMARK(BM_SpeedRatio)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace arco::bench

BENCHMARK_MAIN();
