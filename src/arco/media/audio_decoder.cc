#include "arco/media/audio_decoder.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/channel_layout.h>
#include <libavutil/opt.h>
#include <libswresample/swresample.h>
}

#include <algorithm>

#include "arco/media/av_error.h"

namespace arco::media {

struct AudioDecoder::State {
  ~State() {
    av_frame_free(&frame);
    av_packet_free(&packet);
    swr_free(&swr);
    avcodec_free_context(&codec);
    if (format != nullptr) avformat_close_input(&format);
  }

  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  SwrContext* swr = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;
  int stream_index = -1;
  int swr_rate = 0;
  int decode_errors = 0;
  bool draining = false;
  bool finished = false;
};

AudioDecoder::AudioDecoder(const std::string& path, std::unique_ptr<State> state)
    : path_(path), state_(std::move(state)) {}

AudioDecoder::~AudioDecoder() = default;

StatusOr<std::unique_ptr<AudioDecoder>> AudioDecoder::Open(const std::string& path) {
  av_log_set_level(AV_LOG_QUIET);
  auto s = std::make_unique<State>();
  int rc = avformat_open_input(&s->format, path.c_str(), nullptr, nullptr);
  if (rc < 0) return Status::Error(path + ": cannot open: " + AvError(rc));
  rc = avformat_find_stream_info(s->format, nullptr);
  if (rc < 0) return Status::Error(path + ": cannot read stream info: " + AvError(rc));
  const AVCodec* decoder = nullptr;
  rc = av_find_best_stream(s->format, AVMEDIA_TYPE_AUDIO, -1, -1, &decoder, 0);
  if (rc == AVERROR_STREAM_NOT_FOUND) return Status::Error(path + ": no audio stream");
  if (rc < 0 || decoder == nullptr) {
    return Status::Error(path + ": unsupported audio codec (no decoder available)");
  }
  s->stream_index = rc;
  const AVStream* stream = s->format->streams[rc];
  s->codec = avcodec_alloc_context3(decoder);
  if (s->codec == nullptr) return Status::Error(path + ": out of memory");
  avcodec_parameters_to_context(s->codec, stream->codecpar);
  s->codec->thread_count = 1;  // deterministic and one core
  rc = avcodec_open2(s->codec, decoder, nullptr);
  if (rc < 0) return Status::Error(path + ": cannot open decoder: " + AvError(rc));
  s->frame = av_frame_alloc();
  s->packet = av_packet_alloc();
  if (s->frame == nullptr || s->packet == nullptr) return Status::Error(path + ": out of memory");

  AudioStreamInfo info;
  info.sample_rate_hz = s->codec->sample_rate;
  info.channels = s->codec->ch_layout.nb_channels;
  info.codec = decoder->name;
  if (info.sample_rate_hz > 0 && stream->duration > 0 && stream->time_base.den > 0) {
    info.frames =
        av_rescale_q(stream->duration, stream->time_base, AVRational{1, info.sample_rate_hz});
  }
  std::unique_ptr<AudioDecoder> out(new AudioDecoder(path, std::move(s)));
  out->info_ = info;
  return out;
}

StatusOr<bool> AudioDecoder::Decode(std::vector<float>* mono) {
  State& s = *state_;
  mono->clear();
  while (!s.finished) {
    int rc = avcodec_receive_frame(s.codec, s.frame);
    if (rc == 0) {
      // One decoded frame to mono float at its own rate; the converter is made for the
      // first frame's layout and format, and a later change is refused.
      AVFrame* frame = s.frame;
      if (s.swr == nullptr) {
        AVChannelLayout layout_mono = AV_CHANNEL_LAYOUT_MONO;
        rc = swr_alloc_set_opts2(&s.swr,
                                 &layout_mono,
                                 AV_SAMPLE_FMT_FLT,
                                 frame->sample_rate,
                                 &frame->ch_layout,
                                 static_cast<AVSampleFormat>(frame->format),
                                 frame->sample_rate,
                                 0,
                                 nullptr);
        if (rc < 0 || swr_init(s.swr) < 0) {
          av_frame_unref(frame);
          return Status::Error(path_ + ": cannot convert the audio sample format");
        }
        s.swr_rate = frame->sample_rate;
      }
      if (frame->sample_rate != s.swr_rate || frame->ch_layout.nb_channels != info_.channels) {
        av_frame_unref(frame);
        return Status::Error(path_ + ": sample rate or channel count changes mid-stream");
      }
      mono->resize(static_cast<size_t>(frame->nb_samples) + 64);
      uint8_t* out_planes[1] = {reinterpret_cast<uint8_t*>(mono->data())};
      const int got = swr_convert(s.swr,
                                  out_planes,
                                  static_cast<int>(mono->size()),
                                  const_cast<const uint8_t**>(frame->extended_data),
                                  frame->nb_samples);
      av_frame_unref(frame);
      if (got < 0) return Status::Error(path_ + ": sample conversion failed");
      mono->resize(static_cast<size_t>(got));
      return true;
    }
    if (rc == AVERROR_EOF) break;
    if (rc != AVERROR(EAGAIN)) {
      // A corrupt packet: skip it like players do, but stop on persistent failure.
      if (++s.decode_errors > 100)
        return Status::Error(path_ + ": audio decode error: " + AvError(rc));
    }
    if (s.draining) break;
    rc = av_read_frame(s.format, s.packet);
    if (rc < 0) {
      s.draining = true;
      avcodec_send_packet(s.codec, nullptr);
      continue;
    }
    if (s.packet->stream_index == s.stream_index) {
      rc = avcodec_send_packet(s.codec, s.packet);
      if (rc < 0 && rc != AVERROR(EAGAIN) && ++s.decode_errors > 100) {
        av_packet_unref(s.packet);
        return Status::Error(path_ + ": audio decode error: " + AvError(rc));
      }
    }
    av_packet_unref(s.packet);
  }
  s.finished = true;
  return false;
}

StatusOr<double> VideoStartOnAudioClock(const std::string& path) {
  av_log_set_level(AV_LOG_QUIET);
  AVFormatContext* format = nullptr;
  if (avformat_open_input(&format, path.c_str(), nullptr, nullptr) < 0) {
    return Status::Error(path + ": cannot open");
  }
  double result = 0;
  if (avformat_find_stream_info(format, nullptr) >= 0) {
    const int a = av_find_best_stream(format, AVMEDIA_TYPE_AUDIO, -1, -1, nullptr, 0);
    const int v = av_find_best_stream(format, AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
    const auto start = [&](int index) {
      const AVStream* s = format->streams[index];
      return s->start_time == AV_NOPTS_VALUE ? 0.0 : double(s->start_time) * av_q2d(s->time_base);
    };
    if (a >= 0 && v >= 0) result = start(v) - std::max(0.0, start(a));
  }
  avformat_close_input(&format);
  return result;
}

}  // namespace arco::media
