// Export benchmarks (docs/export.md, "Speed"): each `arco export` format's writer on a
// 3-minute take, 5400 frames at 30 fps of the 155-point SPD cello contact layout (a
// moving body with 2 mm noise per point, the hands included, 1 % gaps), as bytes in
// memory (the file write and the points3d.npy read are extra, a few tens of ms for the
// 10 MB array). The whole command is timed on a real result in docs/export.md.
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <random>

#include "arco/export/export.h"
#include "arco/registry/keypoint_layout.h"

namespace arco::exporter {
namespace {

const ExportData& Take() {
  static const ExportData data = [] {
    const KeypointLayout* layout = FindKeypointLayout("spd_cello_contact");
    ExportData d;
    d.method = "arco";
    d.keypoint_names = layout->names;
    d.fps = 30;
    const int64_t frames = 5400;
    const int64_t points = layout->size();
    d.points_mm.shape = {frames, points, 3};
    d.points_mm.data.resize(frames * points * 3);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-500, 500);
    std::normal_distribution<double> noise(0, 2);
    std::uniform_real_distribution<double> gap(0, 1);
    std::vector<Eigen::Vector3d> shape(points);
    for (auto& p : shape) p = Eigen::Vector3d(u(rng), u(rng), u(rng) + 1000);
    for (int64_t f = 0; f < frames; ++f) {
      const Eigen::Matrix3d r =
          Eigen::AngleAxisd(0.2 * std::sin(0.01 * f), Eigen::Vector3d::UnitZ()).toRotationMatrix();
      for (int64_t p = 0; p < points; ++p) {
        const bool missing = gap(rng) < 0.01;
        const Eigen::Vector3d x = r * shape[p];
        for (int k = 0; k < 3; ++k) d.points_mm.at(f, p, k) = missing ? NAN : x[k] + noise(rng);
      }
    }
    return d;
  }();
  return data;
}

void BM_Csv(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(CsvText(Take()).size());
}
void BM_Trc(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(TrcText(Take(), "take.trc").size());
}
void BM_C3d(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(C3dBytes(Take())->size());
}
void BM_Glb(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(GlbBytes(Take()).size());
}
void BM_Bvh(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(ExportBvh(Take())->text.size());
}
BENCHMARK(BM_Csv)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Trc)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_C3d)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Glb)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Bvh)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace arco::exporter

BENCHMARK_MAIN();
