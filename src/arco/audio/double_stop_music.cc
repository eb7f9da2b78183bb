#include "arco/audio/double_stop_music.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "arco/registry/instruments.h"

namespace arco::audio::testing {
namespace {

constexpr double kEdgeS = 0.06;
constexpr double kVibratoHz = 5.5, kVibratoCents = 20.0;

double Hz(double midi) { return 440.0 * std::exp2((midi - 69.0) / 12.0); }

// f0 of a note at time t (vibrato about the equal-tempered pitch).
double NoteHz(const DoubleStopNote& n, int midi, double t) {
  const double cents =
      n.vibrato ? kVibratoCents * std::sin(2.0 * M_PI * kVibratoHz * (t - n.onset_s)) : 0.0;
  return Hz(midi) * std::exp2(cents / 1200.0);
}

}  // namespace

DoubleStopMusic MakeDoubleStopMusic(const std::string& instrument, int notes, uint32_t seed) {
  DoubleStopMusic music;
  music.instrument = instrument;
  const StatusOr<InstrumentKind> kind = ParseInstrumentKind(instrument);
  const auto& open =
      GetInstrumentInfo(kind.ok() ? *kind : InstrumentKind::kCello).open_midi_low_to_high;
  std::mt19937 rng(seed);
  const int intervals[4] = {9, 4, 7, 12};  // major sixth, major third, fifth, octave
  double t = 0.3;
  for (int i = 0; i < notes; ++i) {
    DoubleStopNote n;
    n.onset_s = t;
    n.offset_s = t + 0.6 + 0.4 * std::uniform_real_distribution<double>(0, 1)(rng);
    n.vibrato = i % 3 == 2;
    if (i % 2 == 0) {
      const int interval = intervals[(i / 2) % 4];
      const int s = std::uniform_int_distribution<int>(0, 2)(rng);
      // Lowest stop on string s that keeps the upper one at or above its open string.
      const int step = open[s + 1] - open[s];
      const int min_stop = std::max(0, step - interval);
      const int stop = min_stop + std::uniform_int_distribution<int>(0, 4)(rng);
      n.low_midi = open[s] + stop;
      n.high_midi = n.low_midi + interval;
    } else {
      const int s = std::uniform_int_distribution<int>(0, 3)(rng);
      n.low_midi = open[s] + std::uniform_int_distribution<int>(0, 7)(rng);
    }
    music.notes.push_back(n);
    t = n.offset_s + (i % 5 == 4 ? 0.8 : 0.2);
  }
  music.duration_s = t + 0.3;
  return music;
}

int DoubleStopMusic::Truth(double time_s, double* low_hz, double* high_hz, double edge_s) const {
  const double edge = std::max(kEdgeS, edge_s);
  *low_hz = *high_hz = 0;
  for (const auto& n : notes) {
    if (time_s < n.onset_s - edge || time_s > n.offset_s + edge) continue;
    if (time_s < n.onset_s + edge || time_s > n.offset_s - edge) return -1;
    *low_hz = NoteHz(n, n.low_midi, time_s);
    if (n.high_midi == 0) return 1;
    *high_hz = NoteHz(n, n.high_midi, time_s);
    return 2;
  }
  return time_s < duration_s ? 0 : -1;
}

std::vector<float> RenderDoubleStopMusic(const DoubleStopMusic& music,
                                         int sample_rate_hz,
                                         uint32_t seed) {
  const double fs = sample_rate_hz;
  std::vector<double> out(static_cast<size_t>(std::ceil(music.duration_s * fs)), 0.0);
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const auto& n : music.notes) {
    const double upper_gain = 0.5 + 0.5 * unit(rng);
    for (int voice = 0; voice < (n.high_midi ? 2 : 1); ++voice) {
      const int midi = voice == 0 ? n.low_midi : n.high_midi;
      const int partials = std::min(20, static_cast<int>(0.45 * fs / (Hz(midi) * 1.02)));
      std::vector<double> amp(partials + 1), phase(partials + 1);
      for (int k = 1; k <= partials; ++k) {
        amp[k] = std::pow(10.0, 4.0 * (2.0 * unit(rng) - 1.0) / 20.0) / k;
        phase[k] = unit(rng);
      }
      const double gain = 0.12 * (voice == 0 ? 1.0 : upper_gain);
      const auto first = static_cast<int64_t>(n.onset_s * fs);
      const auto last = std::min<int64_t>(static_cast<int64_t>(n.offset_s * fs), out.size());
      double cycles = 0;  // phase of the fundamental, integrated
      for (int64_t j = first; j < last; ++j) {
        const double t = j / fs;
        const double envelope = std::min({1.0, (t - n.onset_s) / 0.03, (n.offset_s - t) / 0.03});
        double v = 0;
        for (int k = 1; k <= partials; ++k)
          v += amp[k] * std::sin(2.0 * M_PI * (k * cycles + phase[k]));
        out[j] += gain * envelope * v;
        cycles += NoteHz(n, midi, t) / fs;
        cycles -= std::floor(cycles);
      }
    }
  }
  std::vector<float> samples(out.size());
  const double noise = std::pow(10.0, -60.0 / 20.0);
  for (size_t j = 0; j < out.size(); ++j)
    samples[j] = static_cast<float>(out[j] + noise * gauss(rng));
  return samples;
}

}  // namespace arco::audio::testing
