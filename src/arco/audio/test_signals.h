// Synthetic audio with known truth for tests and benchmarks: phase-accurate
// oscillators driven by an f0(t) function, and WAV writing through libsndfile.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "arco/util/status.h"

namespace arco::audio::testing {

// f0 in Hz at time t in seconds; <= 0 means silence at that time.
using F0Function = std::function<double(double time_s)>;

struct ToneOptions {
  int sample_rate_hz = 44100;
  int harmonics = 1;              // number of partials
  double rolloff = 1.0;           // partial k has amplitude 1 / k^rolloff
  bool skip_fundamental = false;  // missing fundamental
  double amplitude = 0.5;
  double dc = 0.0;
  double noise = 0.0;  // white noise amplitude (seeded)
  double clip = 0.0;   // hard clip at +-clip when > 0
  uint32_t seed = 1;
};

// Renders [0, duration_s) at options.sample_rate_hz, integrating the phase of
// f0(t) (exact for piecewise constant f0 and good to 1e-6 cycles for smooth f0).
std::vector<float> RenderTone(const F0Function& f0, double duration_s, const ToneOptions& options);

// Writes mono or interleaved float samples as 16-bit PCM WAV (or 32-bit float
// when float_format is set).
Status WriteWav(const std::string& path,
                const std::vector<float>& samples,
                int sample_rate_hz,
                int channels = 1,
                bool float_format = false);

// A streaming renderer: calls `next_block` repeatedly so hour-long signals never
// exist in memory; writes a 16-bit mono WAV.
Status WriteToneWavStreaming(const std::string& path,
                             const F0Function& f0,
                             double duration_s,
                             const ToneOptions& options);

std::string TempPath(const std::string& name);

}  // namespace arco::audio::testing
