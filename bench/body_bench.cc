// Skeleton fit benchmark (docs/performance.md, issue 28 part 3): body::FitSkeleton on a
// synthetic performer (testing/skeleton_take.h) over 1738 frames, the one-minute take of
// bench/run_speed.sh, body and right hand, 1 and 2 threads (process CPU time).
#include <benchmark/benchmark.h>

#include "arco/body/skeleton_fit.h"
#include "arco/testing/skeleton_take.h"

namespace arco::body {
namespace {

void BM_FitSkeleton(benchmark::State& state) {
  static const testing::Take take = testing::MakeTake(1738, 2.0, 7);
  SkeletonFitOptions options;
  options.num_threads = static_cast<int>(state.range(0));
  for (auto _ : state) {
    StatusOr<SkeletonFitResult> fit = FitSkeleton(take.noisy, take.names, {}, options);
    if (!fit.ok()) state.SkipWithError(fit.status().message().c_str());
    benchmark::DoNotOptimize(fit);
  }
  state.counters["us_per_frame"] =
      benchmark::Counter(1738.0 * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_FitSkeleton)->Arg(1)->Arg(2)->MeasureProcessCPUTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace arco::body

BENCHMARK_MAIN();
