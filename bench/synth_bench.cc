// Synthesis speed per minute of performance (1800 frames at 30 fps): the whole
// in-memory generation (score, fingering, motion, truth, 2D detections for the
// 20-camera SPD rig) on 1 and 2 threads, and the left hand alone against a
// baseline that also solves IK for every idle finger every frame (the
// straightforward approach arco's animator avoids). No audio (see
// bench/synth_pipeline.sh for the fluidsynth rendering and the CLI pipeline).
#include <benchmark/benchmark.h>

#include "arco/camera/calibration_io.h"
#include "arco/synth/left_hand.h"
#include "arco/synth/synth.h"
#include "arco/util/file_io.h"

#ifndef ARCO_SHARED_DATA_DIR
#define ARCO_SHARED_DATA_DIR "../shared/data"
#endif

namespace arco::synth {
namespace {

// The two-octave scale stretched to one minute.
constexpr double kMinuteTempo = 60.0 / 16.27;

const Rig& SpdRig() {
  static const Rig rig = [] {
    auto text =
        ReadFileToString(std::string(ARCO_SHARED_DATA_DIR) + "/spd/cello_1113_scale_camera.xml");
    return ParseMetashapeXml(*text, "rig.xml")->rig;
  }();
  return rig;
}

void BM_GenerateMinute(benchmark::State& state) {
  SynthOptions o;
  o.tempo_scale = kMinuteTempo;
  o.num_threads = static_cast<int>(state.range(0));
  int frames = 0;
  for (auto _ : state) {
    auto cap = Generate(SpdRig(), o);
    frames = cap->num_frames;
    benchmark::DoNotOptimize(cap->keypoints2d.data.data());
  }
  state.counters["frames"] = frames;
  state.counters["x_real_time"] = benchmark::Counter(frames / o.fps, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_GenerateMinute)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_LeftHandMinute(benchmark::State& state) {
  auto model = *InstrumentModel::Create("cello");
  const ScoreInstrument si = ScoreInstrumentFor(model);
  const Score score = *MakeBuiltInPiece("scale-2oct", si, kMinuteTempo);
  const FingeringPlan plan = *PlanFingering(score, si);
  const Performance perf = *MakePerformance(score, plan, {}, 0);
  const InstrumentTemplate tmpl = *MakeInstrumentTemplate(model);
  const auto hand_model = hand::HandModel::Default(hand::HandSide::kLeft);
  LeftHandOptions lo;
  lo.ik_idle_fingers = state.range(0) == 1;
  const int frames = static_cast<int>(score.duration_s * 30);
  for (auto _ : state) {
    LeftHandAnimator animator(hand_model, model, tmpl, perf, lo);
    for (int f = 0; f < frames; ++f)
      benchmark::DoNotOptimize(animator.Next(f / 30.0).pose.angles_rad[0]);
  }
  state.SetLabel(lo.ik_idle_fingers ? "baseline: IK for every finger"
                                    : "arco: IK for the playing finger");
  state.counters["frames"] = frames;
}
BENCHMARK(BM_LeftHandMinute)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace arco::synth

BENCHMARK_MAIN();
