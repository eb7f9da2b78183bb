// Fuzzes in-memory audio decoding (libsndfile virtual IO: WAV, FLAC, OGG, ...)
// through the exact-timing resampler and one pYIN analysis: any bytes must give
// samples or an error, never a crash or a hang.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "arco/audio/audio_reader.h"
#include "arco/audio/resampler.h"
#include "arco/audio/yin.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  auto reader = arco::audio::OpenAudioFromMemory(&bytes, "fuzz.wav");
  if (!reader.ok()) return 0;
  const int rate = (*reader)->info().sample_rate_hz;
  arco::audio::Resampler resampler(rate, 16000);
  std::vector<float> block(4096), out(4096 * 8 + 64), window;
  arco::audio::YinOptions yin_options;
  arco::audio::YinAnalyzer yin(yin_options);
  int64_t total = 0;
  while (total < (1 << 20)) {  // bound the work per input
    auto n = (*reader)->ReadMono(block.data(), static_cast<int64_t>(block.size()));
    if (!n.ok() || *n == 0) break;
    total += *n;
    resampler.Push(block.data(), *n);
    while (true) {
      const int64_t got = resampler.Pull(out.data(), static_cast<int64_t>(out.size()));
      if (got == 0) break;
      window.insert(window.end(), out.begin(), out.begin() + got);
      if (static_cast<int>(window.size()) >= yin.window_length()) {
        arco::audio::FrameCandidates candidates;
        yin.Analyze(window.data(), &candidates);
        window.clear();
      }
    }
  }
  return 0;
}
