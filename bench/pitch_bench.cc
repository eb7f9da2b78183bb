// Pitch tracking speed (docs/performance.md, Audio). The baseline is textbook
// YIN's O(W * tau_max) difference function; ours uses one FFT pair per frame.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <vector>

#include "arco/audio/double_stops.h"
#include "arco/audio/pitch_hmm.h"
#include "arco/audio/pitch_tracker.h"
#include "arco/audio/resampler.h"
#include "arco/audio/test_signals.h"
#include "arco/audio/yin.h"

namespace {

using namespace arco::audio;

std::vector<float> CelloLike(double seconds, int rate) {
  testing::ToneOptions tone;
  tone.sample_rate_hz = rate;
  tone.harmonics = 20;
  return testing::RenderTone(
      [](double t) { return 65.41 * std::exp2(std::floor(t * 2) / 12.0); }, seconds, tone);
}

YinOptions CelloYin() {
  YinOptions o;
  o.sample_rate_hz = 16000;
  o.min_f0_hz = 60;
  o.max_f0_hz = 2000;
  return o;
}

void BM_YinAnalyzeFrame(benchmark::State& state) {
  YinAnalyzer yin(CelloYin());
  const auto x = CelloLike(1.0, 16000);
  FrameCandidates out;
  size_t offset = 0;
  for (auto _ : state) {
    yin.Analyze(x.data() + offset, &out);
    offset = (offset + 133) % (x.size() - yin.window_length());
    benchmark::DoNotOptimize(out);
  }
}
BENCHMARK(BM_YinAnalyzeFrame);

// Baseline: the difference function summed directly, as in YIN's Eq. 6.
void BM_BaselineDirectDifferenceFrame(benchmark::State& state) {
  YinAnalyzer yin(CelloYin());
  const int w = yin.window_length(), max_lag = yin.max_lag();
  const auto x = CelloLike(1.0, 16000);
  std::vector<double> d(max_lag + 1);
  size_t offset = 0;
  for (auto _ : state) {
    const float* f = x.data() + offset;
    for (int tau = 1; tau <= max_lag; ++tau) {
      double s = 0;
      for (int j = 0; j + tau < w; ++j) {
        const double e = f[j] - f[j + tau];
        s += e * e;
      }
      d[tau] = s;
    }
    offset = (offset + 133) % (x.size() - w);
    benchmark::DoNotOptimize(d.data());
  }
}
BENCHMARK(BM_BaselineDirectDifferenceFrame);

void BM_ResampleOneSecond48kTo16k(benchmark::State& state) {
  const auto x = CelloLike(1.0, 48000);
  std::vector<float> out(20000);
  for (auto _ : state) {
    Resampler r(48000, 16000);
    r.Push(x.data(), static_cast<int64_t>(x.size()));
    r.Finish();
    benchmark::DoNotOptimize(r.Pull(out.data(), static_cast<int64_t>(out.size())));
  }
}
BENCHMARK(BM_ResampleOneSecond48kTo16k);

void BM_HmmPushFrame(benchmark::State& state) {
  PitchHmmOptions o;
  int64_t emitted = 0;
  PitchHmm hmm(o, [&](const DecodedFrame&) { ++emitted; });
  FrameCandidates f;
  f.count = 2;
  f.candidates[0] = {220.0, 0.8, 0.05};
  f.candidates[1] = {110.0, 0.1, 0.2};
  for (auto _ : state) hmm.Push(f);
  benchmark::DoNotOptimize(emitted);
}
BENCHMARK(BM_HmmPushFrame);

// End to end on a 60 s 44.1 kHz file: decode, resample, pYIN, HMM (30 fps, 120 Hz fine).
void BM_TrackPitchSixtySeconds(benchmark::State& state) {
  const std::string path = testing::TempPath("bench60.wav");
  (void)testing::WriteWav(path, CelloLike(60.0, 44100), 44100);
  PitchTrackerOptions o;
  o.range = *InstrumentRangeByName("cello");
  for (auto _ : state) {
    PitchSummary summary;
    auto track = TrackPitchFile(path, o, &summary);
    benchmark::DoNotOptimize(track.ok());
  }
  state.counters["x_real_time"] =
      benchmark::Counter(60.0 * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_TrackPitchSixtySeconds)->Unit(benchmark::kMillisecond);

// Double stops (docs/audio.md, "Double stops"): one cello window holding the sixth G2 +
// E3, the free analysis with the pairs heard on each pair of strings, against the free
// analysis alone (what one frame cost before the pairs on the strings).
std::vector<float> CelloSixth(int rate, int n) {
  testing::ToneOptions tone;
  tone.sample_rate_hz = rate;
  tone.harmonics = 15;
  tone.amplitude = 0.2;
  std::vector<float> x(static_cast<size_t>(n), 0.0f);
  for (const double f : {98.0, 164.81}) {
    const auto y = testing::RenderTone([f](double) { return f; }, 1.0 * n / rate, tone);
    for (int j = 0; j < n && j < static_cast<int>(y.size()); ++j) x[static_cast<size_t>(j)] += y[j];
  }
  return x;
}

void DoubleStopFrame(benchmark::State& state, bool on_strings) {
  DoubleStopOptions o;
  o.range = *InstrumentRangeByName("cello");
  DoubleStopAnalyzer analyzer(o);
  const auto x = CelloSixth(o.range.analysis_rate_hz, analyzer.window_length());
  std::array<PolyNote, 2> notes;
  std::array<std::array<PolyNote, 2>, kStringPairs> pairs;
  for (auto _ : state) {
    benchmark::DoNotOptimize(analyzer.Analyze(x.data(), &notes, on_strings ? &pairs : nullptr));
  }
}
void BM_DoubleStopFrameWithStringPairs(benchmark::State& state) { DoubleStopFrame(state, true); }
BENCHMARK(BM_DoubleStopFrameWithStringPairs);
void BM_BaselineDoubleStopFrameFreeOnly(benchmark::State& state) { DoubleStopFrame(state, false); }
BENCHMARK(BM_BaselineDoubleStopFrameFreeOnly);

}  // namespace

BENCHMARK_MAIN();
