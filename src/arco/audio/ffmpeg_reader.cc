// FFmpeg-backed AudioReader: the best audio stream of any container FFmpeg reads (video
// files, mp3, aac, ...), decoded by media/ (media/audio_decoder.h, the one owner of
// FFmpeg) to mono float at the stream's own rate; rate conversion is ours (resampler.h)
// so timing is exact and identical for every input path. This file also holds the
// reader-independent pieces of audio_reader.h (CheckSamples, TruncationWarning, OpenAudio).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "arco/audio/audio_reader.h"
#include "arco/media/audio_decoder.h"

namespace arco::audio {
namespace {

class FfmpegReader : public AudioReader {
 public:
  static StatusOr<std::unique_ptr<AudioReader>> Open(const std::string& path) {
    ARCO_ASSIGN_OR_RETURN(std::unique_ptr<media::AudioDecoder> decoder,
                          media::AudioDecoder::Open(path));
    const media::AudioStreamInfo& stream = decoder->info();
    const int rate = stream.sample_rate_hz;
    if (rate < kMinRateHz || rate > kMaxRateHz) {
      return Status::Error(path +
                           ": unsupported sample rate (need 1-768 kHz): " + std::to_string(rate));
    }
    if (stream.channels <= 0 || stream.channels > 1024) {
      return Status::Error(path + ": invalid channel count " + std::to_string(stream.channels));
    }
    std::unique_ptr<FfmpegReader> r(new FfmpegReader(path, std::move(decoder)));
    r->info_.sample_rate_hz = rate;
    r->info_.channels = stream.channels;
    r->info_.format = "ffmpeg " + stream.codec;
    r->info_.source = path;
    r->info_.frames = stream.frames;
    return std::unique_ptr<AudioReader>(std::move(r));
  }

  StatusOr<int64_t> ReadMono(float* out, int64_t max_frames) override {
    int64_t total = 0;
    while (total < max_frames) {
      if (pending_pos_ < pending_.size()) {
        const int64_t n = std::min<int64_t>(max_frames - total,
                                            static_cast<int64_t>(pending_.size() - pending_pos_));
        std::copy_n(pending_.data() + pending_pos_, n, out + total);
        pending_pos_ += static_cast<size_t>(n);
        total += n;
        continue;
      }
      if (finished_) break;
      ARCO_ASSIGN_OR_RETURN(const bool more, decoder_->Decode(&pending_));
      pending_pos_ = 0;
      if (!more) {
        finished_ = true;
        continue;
      }
      const int64_t got = static_cast<int64_t>(pending_.size());
      ARCO_RETURN_IF_ERROR(
          CheckSamples(pending_.data(), got, 1, converted_, info_.sample_rate_hz, name_));
      converted_ += got;
    }
    return total;
  }

 private:
  FfmpegReader(const std::string& path, std::unique_ptr<media::AudioDecoder> decoder)
      : name_(path), decoder_(std::move(decoder)) {}

  std::string name_;
  std::unique_ptr<media::AudioDecoder> decoder_;
  bool finished_ = false;
  std::vector<float> pending_;  // the last decoded frame, mono, native rate
  size_t pending_pos_ = 0;
  int64_t converted_ = 0;  // samples decoded before pending_ (the index of pending_[0])
};

}  // namespace

StatusOr<std::unique_ptr<AudioReader>> OpenAudioWithFfmpeg(const std::string& path) {
  return FfmpegReader::Open(path);
}

Status CheckSamples(const float* values,
                    int64_t count,
                    int channels,
                    int64_t first_sample,
                    int rate_hz,
                    const std::string& source) {
  for (int64_t i = 0; i < count; ++i) {
    const float v = values[i];
    if (v >= -1e6f && v <= 1e6f) continue;  // false for NaN
    const int64_t sample = first_sample + i / std::max(channels, 1);
    char text[160];
    std::snprintf(text,
                  sizeof(text),
                  ": sample %lld (%.4f s) is %g; audio samples must be finite (a float "
                  "recording holds about -1..1)",
                  static_cast<long long>(sample),
                  rate_hz > 0 ? static_cast<double>(sample) / rate_hz : 0.0,
                  static_cast<double>(v));
    return Status::Error(source + text);
  }
  return Status::Ok();
}

std::string TruncationWarning(const AudioInfo& info, int64_t delivered) {
  if (delivered < 0) delivered = info.frames - info.missing_frames;
  if (info.frames <= 0 || delivered >= info.frames || info.sample_rate_hz <= 0) return "";
  const double rate = info.sample_rate_hz;
  char text[160];
  std::snprintf(text,
                sizeof(text),
                ": truncated: the header promises %lld samples (%.3f s), the file holds %lld "
                "(%.3f s missing)",
                static_cast<long long>(info.frames),
                static_cast<double>(info.frames) / rate,
                static_cast<long long>(delivered),
                static_cast<double>(info.frames - delivered) / rate);
  return info.source + text;
}

StatusOr<std::unique_ptr<AudioReader>> OpenAudio(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return Status::Error(path + ": no such file");
  if (std::filesystem::is_directory(path, ec)) return Status::Error(path + ": is a directory");
  if (std::filesystem::file_size(path, ec) == 0) return Status::Error(path + ": empty file");
  auto sndfile = OpenAudioWithSndfile(path);
  if (sndfile.ok()) return sndfile;
  auto ffmpeg = OpenAudioWithFfmpeg(path);
  if (ffmpeg.ok()) return ffmpeg;
  return Status::Error(path + ": cannot decode audio (libsndfile: " +
                       sndfile.status().message().substr(path.size() + 2) +
                       "; FFmpeg: " + ffmpeg.status().message().substr(path.size() + 2) + ")");
}

}  // namespace arco::audio
