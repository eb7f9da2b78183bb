#include "arco/audio/test_signals.h"

#include <sndfile.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

namespace arco::audio::testing {
namespace {

// Oscillator state: phase of the fundamental in cycles (double; wraps).
struct Oscillator {
  double phase = 0;
  std::mt19937 rng;
  std::normal_distribution<double> gauss{0.0, 1.0};
};

void RenderInto(const F0Function& f0,
                int64_t first,
                int64_t count,
                const ToneOptions& o,
                Oscillator* osc,
                float* out) {
  const double fs = o.sample_rate_hz;
  for (int64_t i = 0; i < count; ++i) {
    const double t = static_cast<double>(first + i) / fs;
    const double f = f0(t);
    double v = 0;
    if (f > 0) {
      for (int k = o.skip_fundamental ? 2 : 1; k <= o.harmonics; ++k) {
        if (k * f >= fs / 2) break;
        v += std::sin(2.0 * M_PI * k * osc->phase + 0.3 * k) / std::pow(k, o.rolloff);
      }
      v *= o.amplitude;
      // Advance by the mid-sample frequency (trapezoid rule on f0).
      const double f_next = f0(t + 1.0 / fs);
      osc->phase += 0.5 * (f + (f_next > 0 ? f_next : f)) / fs;
      osc->phase -= std::floor(osc->phase);
    }
    v += o.dc;
    if (o.noise > 0) v += o.noise * osc->gauss(osc->rng);
    if (o.clip > 0) v = std::clamp(v, -o.clip, o.clip);
    out[i] = static_cast<float>(v);
  }
}

}  // namespace

std::vector<float> RenderTone(const F0Function& f0, double duration_s, const ToneOptions& o) {
  const int64_t n = static_cast<int64_t>(std::llround(duration_s * o.sample_rate_hz));
  std::vector<float> out(static_cast<size_t>(n));
  Oscillator osc;
  osc.rng.seed(o.seed);
  RenderInto(f0, 0, n, o, &osc, out.data());
  return out;
}

Status WriteWav(const std::string& path,
                const std::vector<float>& samples,
                int sample_rate_hz,
                int channels,
                bool float_format) {
  SF_INFO info{};
  info.samplerate = sample_rate_hz;
  info.channels = channels;
  info.format = SF_FORMAT_WAV | (float_format ? SF_FORMAT_FLOAT : SF_FORMAT_PCM_16);
  SNDFILE* f = sf_open(path.c_str(), SFM_WRITE, &info);
  if (f == nullptr) return Status::Error(path + ": cannot write: " + sf_strerror(nullptr));
  sf_command(f, SFC_SET_CLIPPING, nullptr, SF_TRUE);
  const sf_count_t frames = static_cast<sf_count_t>(samples.size() / channels);
  const sf_count_t written = sf_writef_float(f, samples.data(), frames);
  sf_close(f);
  if (written != frames) return Status::Error(path + ": short write");
  return Status::Ok();
}

Status WriteToneWavStreaming(const std::string& path,
                             const F0Function& f0,
                             double duration_s,
                             const ToneOptions& o) {
  SF_INFO info{};
  info.samplerate = o.sample_rate_hz;
  info.channels = 1;
  info.format = SF_FORMAT_WAV | SF_FORMAT_PCM_16;
  SNDFILE* f = sf_open(path.c_str(), SFM_WRITE, &info);
  if (f == nullptr) return Status::Error(path + ": cannot write: " + sf_strerror(nullptr));
  sf_command(f, SFC_SET_CLIPPING, nullptr, SF_TRUE);
  const int64_t n = static_cast<int64_t>(std::llround(duration_s * o.sample_rate_hz));
  Oscillator osc;
  osc.rng.seed(o.seed);
  std::vector<float> block(1 << 16);
  for (int64_t first = 0; first < n; first += static_cast<int64_t>(block.size())) {
    const int64_t count = std::min<int64_t>(static_cast<int64_t>(block.size()), n - first);
    RenderInto(f0, first, count, o, &osc, block.data());
    if (sf_writef_float(f, block.data(), count) != count) {
      sf_close(f);
      return Status::Error(path + ": short write");
    }
  }
  sf_close(f);
  return Status::Ok();
}

namespace {
// The per-process scratch folder; removed when the test process exits.
struct ScratchDir {
  std::filesystem::path path;
  ScratchDir()
      : path(std::filesystem::temp_directory_path() /
             ("arco_audio_test_" + std::to_string(::getpid()))) {}
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
};
}  // namespace

std::string TempPath(const std::string& name) {
  static ScratchDir scratch;
  std::filesystem::create_directories(scratch.path);
  return (scratch.path / name).string();
}

}  // namespace arco::audio::testing
