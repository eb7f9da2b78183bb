// Streaming audio decoding. Conventions for the whole audio layer:
// - Samples are float in [-1, 1], mono (all channels averaged: downmix).
// - Sample index n of a stream at rate fs is at time n / fs seconds; index 0 is
//   the first decoded sample (container start offsets are ignored).
// - Readers never hold the whole file: callers pull blocks (ReadMono).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "arco/util/status.h"

namespace arco::audio {

// Sample rates outside this range are rejected as unsupported.
constexpr int kMinRateHz = 1000;
constexpr int kMaxRateHz = 768000;

struct AudioInfo {
  int sample_rate_hz = 0;
  int channels = 0;
  // Frames promised by the header; -1 when the container does not say (FFmpeg
  // streams). A file that delivers fewer is reported as truncated.
  int64_t frames = -1;
  std::string format;  // e.g. "WAV (Microsoft) 16 bit PCM" or "ffmpeg aac"
  std::string source;  // the file (or name) opened, for messages
  // Of `frames`, how many the file is known at open time not to hold (a WAV whose data
  // chunk is cut short); 0 when none or unknown.
  int64_t missing_frames = 0;
};

// One line for a source that delivered fewer frames than its header promised ("" when it
// did not): "FILE: truncated: the header promises N samples (X s), the file holds M
// (Y s missing)". `delivered` is what was decoded (-1: what the file is known to hold).
// Every command that decodes audio reports it through this one function.
std::string TruncationWarning(const AudioInfo& info, int64_t delivered = -1);

// The one check of decoded samples, used by every reader and by the Python bindings'
// samples: each finite and within +-1e6 (float files hold about +-1). A NaN or an infinity
// would poison every FFT downstream, and replacing it would hide a broken file, so it is
// an error: "SOURCE: sample N (T s) is nan; ...". `values` are `channels` interleaved
// values per sample, the first of them sample `first_sample`.
Status CheckSamples(const float* values,
                    int64_t count,
                    int channels,
                    int64_t first_sample,
                    int rate_hz,
                    const std::string& source);

class AudioReader {
 public:
  virtual ~AudioReader() = default;
  const AudioInfo& info() const { return info_; }
  // Reads up to `max_frames` mono samples into `out`; returns the number read,
  // 0 at the end of the stream, or an error (corrupt data mid-stream).
  virtual StatusOr<int64_t> ReadMono(float* out, int64_t max_frames) = 0;

 protected:
  AudioInfo info_;
};

// Opens WAV/FLAC/OGG/AIFF... with libsndfile, anything else (audio track of a
// video, mp3, aac, ...) with FFmpeg. Errors name the file and the problem.
StatusOr<std::unique_ptr<AudioReader>> OpenAudio(const std::string& path);

// libsndfile only (also used directly by tests).
StatusOr<std::unique_ptr<AudioReader>> OpenAudioWithSndfile(const std::string& path);
// FFmpeg only (through media/audio_decoder.h): the best audio stream of any container.
StatusOr<std::unique_ptr<AudioReader>> OpenAudioWithFfmpeg(const std::string& path);
// Decodes an in-memory file image with libsndfile's virtual IO (fuzzing and
// tests). `bytes` must outlive the reader.
StatusOr<std::unique_ptr<AudioReader>> OpenAudioFromMemory(const std::string* bytes,
                                                           const std::string& name);

}  // namespace arco::audio
