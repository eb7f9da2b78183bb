// Refinement benchmarks (docs/performance.md, section "Refinement"): the whole
// audio-guided refinement of a 3-minute cello piece (5400 frames at 30 fps) in arco and
// paper mode, 1 and 2 threads, beside the vision-only pass-through as a baseline measured
// in the same run (it only copies the hands: the floor of any refinement).
#include <benchmark/benchmark.h>

#include "arco/refine/refine.h"
#include "arco/refine/test_scene.h"

namespace arco::refine {
namespace {

// 5400 frames: a repeated phrase with string crossings, shifts, vibrato, open strings,
// rests (about 75% of the frames pressed), with the audio's notes for arco mode.
const testing::Scene& Piece() {
  static const testing::Scene scene = [] {
    const std::vector<testing::SceneNote> phrase = {{2, 1, 2, 15},
                                                    {2, 2, 3, 15},
                                                    {2, 4, 5, 15},
                                                    {1, 1, 2, 15},
                                                    {1, 3, 4, 30, 25},
                                                    {0, 0, 0, 10},
                                                    {1, 2, 8, 45, 20},
                                                    {1, 0, 0, 15},
                                                    {3, 1, 2, 15},
                                                    {3, 4, 5, 30, 15},
                                                    {4, 2, 3, 20},
                                                    {4, 4, 5, 30, 20},
                                                    {0, 0, 0, 10},
                                                    {2, 1, 7, 15},
                                                    {2, 3, 9, 30, 25},
                                                    {3, 2, 3, 20},
                                                    {1, 0, 0, 10},
                                                    {2, 1, 2, 30, 20},
                                                    {0, 0, 0, 10}};
    std::vector<testing::SceneNote> notes;
    int total = 0;
    while (total < 5400) {
      for (auto n : phrase) {
        n.frames = std::min(n.frames, 5400 - total);
        if (n.frames <= 0) break;
        notes.push_back(n);
        total += n.frames;
      }
    }
    testing::Scene out = testing::MakeScene(InstrumentKind::kCello, notes);
    // The audio layer's notes (onsets a quarter frame late): arco's note boundaries run.
    out.input.audio_notes = testing::AudioNotesOf(*out.model, notes, 30.0, 1.0 / 120.0);
    return out;
  }();
  return scene;
}

void Run(benchmark::State& state, RefineMode mode) {
  const testing::Scene& scene = Piece();
  RefineOptions options;
  options.mode = mode;
  options.num_threads = static_cast<int>(state.range(0));
  int pressed = 0, solves = 0, iterations = 0;
  for (auto _ : state) {
    const RefineResult r = Refine(scene.input, options);
    pressed = r.summary.pressed;
    solves = r.summary.ik_solves;
    iterations = r.summary.ik_iterations;
    benchmark::DoNotOptimize(r.hand.data());
  }
  const double frames = static_cast<double>(scene.input.pitch.size());
  state.counters["frames"] = frames;
  state.counters["pressed"] = pressed;
  state.counters["ik_solves"] = solves;
  state.counters["ik_iterations"] = iterations;
  // Seconds of wall time per frame (printed with an SI prefix: u = microseconds).
  state.counters["per_frame"] =
      benchmark::Counter(frames * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_RefineVisionBaseline(benchmark::State& state) { Run(state, RefineMode::kVision); }
void BM_RefinePaper(benchmark::State& state) { Run(state, RefineMode::kPaper); }
void BM_RefineArco(benchmark::State& state) { Run(state, RefineMode::kArco); }

BENCHMARK(BM_RefineVisionBaseline)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RefinePaper)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RefineArco)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace arco::refine

BENCHMARK_MAIN();
