// Detector inference latency (docs/performance.md, section "Detect"): one forward pass
// of each converted MediaPipe model with cv::dnn on 2 threads (detect::Network::Run:
// NHWC -> NCHW copy, forward, outputs copied out) on a fixed pseudo-random input of
// the model's size (the time does not depend on the content). Wall time is what counts
// (OpenCV's pool threads do the work, not the calling thread), so the benchmarks
// report real time.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <random>
#include <vector>

#include "arco/detect/network.h"

namespace arco::detect {
namespace {

void BM_Inference(benchmark::State& state) {
  const ModelInfo& info = AllModels()[state.range(0)];
  state.SetLabel(info.name);
  NetworkOptions options;
  options.num_threads = 2;
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
BENCHMARK(BM_Inference)->DenseRange(0, 7)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace arco::detect
BENCHMARK_MAIN();
