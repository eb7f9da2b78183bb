// Instrument layer speed: the clip-level template fit and per-frame strings for a
// 3-minute clip (5400 frames at 30 fps), against the SPD-style baseline that builds the
// strings of every frame straight from its four nut/bridge keypoints (no template).
// Synthetic cello clip: 2 mm keypoint noise, 6% gross outlier points, 10% missing points,
// Metashape-like units. Single-threaded.
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "arco/instrument/contact.h"
#include "arco/instrument/pose_smoothing.h"
#include "arco/instrument/strings.h"
#include "arco/instrument/template_fit.h"

namespace arco {
namespace {

constexpr int kFrames = 5400;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

const InstrumentModel& Cello() {
  static const InstrumentModel model = *InstrumentModel::Create("cello");
  return model;
}

struct Clip {
  std::vector<Eigen::Matrix3Xd> keypoints;
  std::vector<FrontHint> hints;
};

const Clip& MakeClip() {
  static const Clip clip = [] {
    const Eigen::Vector3d shape[7] = {{881, 0, -25},
                                      {695, 11.95, 0},
                                      {695, -11.95, 0},
                                      {0, 24.1, 0},
                                      {0, -24.1, 0},
                                      {-370, 0, -70},
                                      {-670, 0, -160}};
    std::mt19937 rng(2024);
    std::normal_distribution<double> noise(0.0, 2.0);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    Clip c;
    for (int f = 0; f < kFrames; ++f) {
      SimMatrix3d world_from_instrument;
      const double t = 0.05 * f;
      world_from_instrument.rotation =
          (Eigen::AngleAxisd(1.2 + 0.08 * std::sin(t), Eigen::Vector3d::UnitZ()) *
           Eigen::AngleAxisd(0.3 + 0.05 * std::cos(0.7 * t), Eigen::Vector3d::UnitX()))
              .toRotationMatrix();
      world_from_instrument.translation =
          Eigen::Vector3d(0.1 + 0.01 * std::sin(0.3 * t), -0.2, 1.9);
      world_from_instrument.scale = 1.0 / 2020.0;  // world units per mm
      Eigen::Matrix3Xd kp = Eigen::Matrix3Xd::Constant(3, 9, kNaN);
      for (int k = 0; k < 7; ++k) {
        Eigen::Vector3d p = shape[k] + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
        if (uniform(rng) < 0.06) p += Eigen::Vector3d(120, -60, 40);
        if (uniform(rng) >= 0.1) kp.col(k) = world_from_instrument * p;
      }
      c.keypoints.push_back(kp);
      c.hints.push_back({FrontHint::Kind::kPerformerPoint,
                         world_from_instrument * Eigen::Vector3d(450, 50, -300)});
    }
    return c;
  }();
  return clip;
}

// Template fit over the clip + strings for every frame.
void BM_FitInstrumentAndStrings(benchmark::State& state) {
  const Clip& clip = MakeClip();
  InstrumentFitOptions options;
  options.num_threads = 1;
  for (auto _ : state) {
    auto fit = FitInstrument(Cello(), clip.keypoints, clip.hints, options);
    size_t with_strings = 0;
    for (const InstrumentFramePose& frame : fit->frames) {
      if (!frame.has_pose()) continue;
      const std::vector<StringSegment> strings =
          StringsAt(fit->instrument, frame.world_from_instrument);
      benchmark::DoNotOptimize(strings.data());
      ++with_strings;
    }
    benchmark::DoNotOptimize(with_strings);
  }
  state.counters["s_per_frame"] =
      benchmark::Counter(static_cast<double>(kFrames) * state.iterations(),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_FitInstrumentAndStrings)->Unit(benchmark::kMillisecond);

// Baseline (SPD style): strings of every frame from its own nut/bridge keypoints.
void BM_BaselineStringsPerFrameFromEdges(benchmark::State& state) {
  const Clip& clip = MakeClip();
  const InstrumentModel& model = Cello();
  for (auto _ : state) {
    size_t with_strings = 0;
    for (int f = 0; f < kFrames; ++f) {
      const Eigen::Matrix3Xd& kp = clip.keypoints[f];
      const StringEdges edges{kp.col(model.nut_l()),
                              kp.col(model.nut_r()),
                              kp.col(model.bridge_l()),
                              kp.col(model.bridge_r())};
      auto g = GeometryFromEdges(model, edges, clip.hints[f]);
      if (g.ok()) ++with_strings;
    }
    benchmark::DoNotOptimize(with_strings);
  }
  state.counters["s_per_frame"] =
      benchmark::Counter(static_cast<double>(kFrames) * state.iterations(),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_BaselineStringsPerFrameFromEdges)->Unit(benchmark::kMillisecond);

// Smoothing the fitted poses (sigma 2 frames) and recomputing the strings.
void BM_SmoothPosesAndStrings(benchmark::State& state) {
  const Clip& clip = MakeClip();
  auto fit = FitInstrument(Cello(), clip.keypoints, clip.hints);
  for (auto _ : state) {
    const std::vector<InstrumentFramePose> smooth = SmoothFramePoses(fit->frames);
    for (const InstrumentFramePose& frame : smooth) {
      if (frame.has_pose())
        benchmark::DoNotOptimize(StringsAt(fit->instrument, frame.world_from_instrument));
    }
  }
  state.counters["s_per_frame"] =
      benchmark::Counter(static_cast<double>(kFrames) * state.iterations(),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_SmoothPosesAndStrings)->Unit(benchmark::kMillisecond);

// One pitch -> contact query on each of the four strings.
void BM_ContactCandidates(benchmark::State& state) {
  ContactOptions options;
  options.physical_correction = state.range(0) != 0;
  double f0 = 130.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(ContactCandidates(Cello(), f0, options));
    f0 = f0 < 600 ? f0 * 1.01 : 130.0;
  }
}
BENCHMARK(BM_ContactCandidates)->Arg(0)->Arg(1);

}  // namespace
}  // namespace arco

BENCHMARK_MAIN();
