// FFmpeg-backed AudioReader: the best audio stream of any container FFmpeg
// reads (video files, mp3, aac, ...). libswresample only converts to mono float
// at the stream's own rate; rate conversion is ours (resampler.h) so timing is
// exact and identical for every input path.
extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/channel_layout.h>
#include <libavutil/opt.h>
#include <libswresample/swresample.h>
}

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "arco/audio/audio_reader.h"

namespace arco::audio {
namespace {

std::string AvError(int code) {
  char buffer[AV_ERROR_MAX_STRING_SIZE] = {0};
  av_strerror(code, buffer, sizeof(buffer));
  return buffer;
}

class FfmpegReader : public AudioReader {
 public:
  ~FfmpegReader() override {
    av_frame_free(&frame_);
    av_packet_free(&packet_);
    swr_free(&swr_);
    avcodec_free_context(&codec_);
    if (format_ != nullptr) avformat_close_input(&format_);
  }

  static StatusOr<std::unique_ptr<AudioReader>> Open(const std::string& path) {
    av_log_set_level(AV_LOG_QUIET);
    std::unique_ptr<FfmpegReader> r(new FfmpegReader());
    r->name_ = path;
    int rc = avformat_open_input(&r->format_, path.c_str(), nullptr, nullptr);
    if (rc < 0) return Status::Error(path + ": cannot open: " + AvError(rc));
    rc = avformat_find_stream_info(r->format_, nullptr);
    if (rc < 0) return Status::Error(path + ": cannot read stream info: " + AvError(rc));
    const AVCodec* decoder = nullptr;
    rc = av_find_best_stream(r->format_, AVMEDIA_TYPE_AUDIO, -1, -1, &decoder, 0);
    if (rc == AVERROR_STREAM_NOT_FOUND) return Status::Error(path + ": no audio stream");
    if (rc < 0 || decoder == nullptr) {
      return Status::Error(path + ": unsupported audio codec (no decoder available)");
    }
    r->stream_index_ = rc;
    AVStream* stream = r->format_->streams[rc];
    r->codec_ = avcodec_alloc_context3(decoder);
    if (r->codec_ == nullptr) return Status::Error(path + ": out of memory");
    avcodec_parameters_to_context(r->codec_, stream->codecpar);
    r->codec_->thread_count = 1;  // deterministic and one core
    rc = avcodec_open2(r->codec_, decoder, nullptr);
    if (rc < 0) return Status::Error(path + ": cannot open decoder: " + AvError(rc));
    const int rate = r->codec_->sample_rate;
    const int channels = r->codec_->ch_layout.nb_channels;
    if (rate < kMinRateHz || rate > kMaxRateHz) {
      return Status::Error(path +
                           ": unsupported sample rate (need 1-768 kHz): " + std::to_string(rate));
    }
    if (channels <= 0 || channels > 1024) {
      return Status::Error(path + ": invalid channel count " + std::to_string(channels));
    }
    r->info_.sample_rate_hz = rate;
    r->info_.channels = channels;
    r->info_.format = std::string("ffmpeg ") + decoder->name;
    r->info_.source = path;
    if (stream->duration > 0 && stream->time_base.den > 0) {
      r->info_.frames = av_rescale_q(stream->duration, stream->time_base, AVRational{1, rate});
    }
    r->frame_ = av_frame_alloc();
    r->packet_ = av_packet_alloc();
    if (r->frame_ == nullptr || r->packet_ == nullptr)
      return Status::Error(path + ": out of memory");
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
      Status s = DecodeMore();
      if (!s.ok()) return s;
    }
    return total;
  }

 private:
  FfmpegReader() = default;

  // Converts one decoded frame into pending_ (mono float, native rate).
  Status Convert() {
    if (swr_ == nullptr) {
      AVChannelLayout mono = AV_CHANNEL_LAYOUT_MONO;
      int rc = swr_alloc_set_opts2(&swr_,
                                   &mono,
                                   AV_SAMPLE_FMT_FLT,
                                   frame_->sample_rate,
                                   &frame_->ch_layout,
                                   static_cast<AVSampleFormat>(frame_->format),
                                   frame_->sample_rate,
                                   0,
                                   nullptr);
      if (rc < 0 || swr_init(swr_) < 0) {
        return Status::Error(name_ + ": cannot convert the audio sample format");
      }
      swr_rate_ = frame_->sample_rate;
    }
    if (frame_->sample_rate != swr_rate_ || frame_->ch_layout.nb_channels != info_.channels) {
      return Status::Error(name_ + ": sample rate or channel count changes mid-stream");
    }
    pending_.resize(static_cast<size_t>(frame_->nb_samples) + 64);
    uint8_t* out_planes[1] = {reinterpret_cast<uint8_t*>(pending_.data())};
    const int got = swr_convert(swr_,
                                out_planes,
                                static_cast<int>(pending_.size()),
                                const_cast<const uint8_t**>(frame_->extended_data),
                                frame_->nb_samples);
    if (got < 0) return Status::Error(name_ + ": sample conversion failed");
    pending_.resize(static_cast<size_t>(got));
    ARCO_RETURN_IF_ERROR(
        CheckSamples(pending_.data(), got, 1, converted_, info_.sample_rate_hz, name_));
    converted_ += got;
    pending_pos_ = 0;
    return Status::Ok();
  }

  Status DecodeMore() {
    while (true) {
      int rc = avcodec_receive_frame(codec_, frame_);
      if (rc == 0) {
        Status s = Convert();
        av_frame_unref(frame_);
        return s;
      }
      if (rc == AVERROR_EOF) {
        finished_ = true;
        return Status::Ok();
      }
      if (rc != AVERROR(EAGAIN)) {
        // A corrupt packet: skip it like players do, but stop on persistent failure.
        if (++decode_errors_ > 100)
          return Status::Error(name_ + ": audio decode error: " + AvError(rc));
      }
      if (draining_) {
        finished_ = true;
        return Status::Ok();
      }
      rc = av_read_frame(format_, packet_);
      if (rc < 0) {
        draining_ = true;
        avcodec_send_packet(codec_, nullptr);
        continue;
      }
      if (packet_->stream_index == stream_index_) {
        rc = avcodec_send_packet(codec_, packet_);
        if (rc < 0 && rc != AVERROR(EAGAIN) && ++decode_errors_ > 100) {
          av_packet_unref(packet_);
          return Status::Error(name_ + ": audio decode error: " + AvError(rc));
        }
      }
      av_packet_unref(packet_);
    }
  }

  std::string name_;
  AVFormatContext* format_ = nullptr;
  AVCodecContext* codec_ = nullptr;
  SwrContext* swr_ = nullptr;
  AVFrame* frame_ = nullptr;
  AVPacket* packet_ = nullptr;
  int stream_index_ = -1;
  int swr_rate_ = 0;
  int decode_errors_ = 0;
  bool draining_ = false;
  bool finished_ = false;
  std::vector<float> pending_;
  size_t pending_pos_ = 0;
  int64_t converted_ = 0;  // samples converted so far (the index of pending_[0])
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
