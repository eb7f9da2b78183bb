#include "arco/media/test_audio_video.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/channel_layout.h>
#include <libavutil/opt.h>
}

#include <algorithm>
#include <cmath>

namespace arco::media::testing {
namespace {

struct Muxer {
  AVFormatContext* format = nullptr;
  AVCodecContext* video = nullptr;
  AVCodecContext* audio = nullptr;
  AVStream* video_stream = nullptr;
  AVStream* audio_stream = nullptr;
  AVPacket* packet = av_packet_alloc();
  ~Muxer() {
    av_packet_free(&packet);
    avcodec_free_context(&video);
    avcodec_free_context(&audio);
    if (format != nullptr) {
      if (format->pb != nullptr) avio_closep(&format->pb);
      avformat_free_context(format);
    }
  }
  // Sends `frame` (nullptr flushes) and writes every packet that comes out.
  bool Encode(AVCodecContext* codec, AVStream* stream, AVFrame* frame) {
    if (avcodec_send_frame(codec, frame) < 0) return false;
    while (true) {
      const int rc = avcodec_receive_packet(codec, packet);
      if (rc == AVERROR(EAGAIN) || rc == AVERROR_EOF) return true;
      if (rc < 0) return false;
      av_packet_rescale_ts(packet, codec->time_base, stream->time_base);
      packet->stream_index = stream->index;
      if (av_interleaved_write_frame(format, packet) < 0) return false;
    }
  }
};

}  // namespace

Status WriteTestVideo(const std::string& path, const TestVideo& v) {
  auto fail = [&](const std::string& what) { return Status::Error(path + ": " + what); };
  Muxer m;
  if (avformat_alloc_output_context2(&m.format, nullptr, "matroska", path.c_str()) < 0) {
    return fail("cannot create muxer");
  }
  const AVCodec* ffv1 = avcodec_find_encoder(AV_CODEC_ID_FFV1);
  if (ffv1 == nullptr) return fail("no FFV1 encoder");
  m.video = avcodec_alloc_context3(ffv1);
  m.video->width = v.width;
  m.video->height = v.height;
  m.video->pix_fmt = AV_PIX_FMT_GRAY8;
  m.video->time_base = AVRational{1, v.fps};
  m.video->framerate = AVRational{v.fps, 1};
  m.video->thread_count = 1;
  if (m.format->oformat->flags & AVFMT_GLOBALHEADER) m.video->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  if (avcodec_open2(m.video, ffv1, nullptr) < 0) return fail("cannot open FFV1 encoder");
  m.video_stream = avformat_new_stream(m.format, nullptr);
  avcodec_parameters_from_context(m.video_stream->codecpar, m.video);
  m.video_stream->time_base = m.video->time_base;
  m.video_stream->avg_frame_rate = AVRational{v.fps, 1};
  if (!v.audio.empty()) {
    const AVCodec* enc = avcodec_find_encoder_by_name(v.audio_codec.c_str());
    if (enc == nullptr) return fail("no " + v.audio_codec + " encoder");
    m.audio = avcodec_alloc_context3(enc);
    m.audio->sample_rate = v.audio_rate_hz;
    AVChannelLayout mono = AV_CHANNEL_LAYOUT_MONO;
    av_channel_layout_copy(&m.audio->ch_layout, &mono);
    m.audio->sample_fmt = enc->sample_fmts ? enc->sample_fmts[0] : AV_SAMPLE_FMT_S16;
    m.audio->time_base = AVRational{1, v.audio_rate_hz};
    m.audio->bit_rate = 128000;
    if (m.format->oformat->flags & AVFMT_GLOBALHEADER)
      m.audio->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    if (avcodec_open2(m.audio, enc, nullptr) < 0) return fail("cannot open audio encoder");
    m.audio_stream = avformat_new_stream(m.format, nullptr);
    avcodec_parameters_from_context(m.audio_stream->codecpar, m.audio);
    m.audio_stream->time_base = m.audio->time_base;
  }
  if (avio_open(&m.format->pb, path.c_str(), AVIO_FLAG_WRITE) < 0) return fail("cannot write");
  if (avformat_write_header(m.format, nullptr) < 0) return fail("cannot write header");

  AVFrame* frame = av_frame_alloc();
  frame->format = AV_PIX_FMT_GRAY8;
  frame->width = v.width;
  frame->height = v.height;
  av_frame_get_buffer(frame, 0);
  bool ok = true;
  // Audio frames of 1024 samples interleaved with the video by time.
  const int chunk = m.audio != nullptr && m.audio->frame_size > 0 ? m.audio->frame_size : 1024;
  size_t audio_pos = 0;
  auto write_audio_until = [&](double t_s, bool all) {
    while (ok && m.audio != nullptr && audio_pos < v.audio.size() &&
           (all || audio_pos < t_s * v.audio_rate_hz)) {
      const int n = static_cast<int>(std::min<size_t>(chunk, v.audio.size() - audio_pos));
      AVFrame* a = av_frame_alloc();
      a->format = m.audio->sample_fmt;
      a->nb_samples = (m.audio->frame_size > 0) ? m.audio->frame_size : n;
      av_channel_layout_copy(&a->ch_layout, &m.audio->ch_layout);
      a->sample_rate = v.audio_rate_hz;
      av_frame_get_buffer(a, 0);
      av_samples_set_silence(a->data, 0, a->nb_samples, 1, m.audio->sample_fmt);
      for (int i = 0; i < n; ++i) {
        const float s = std::clamp(v.audio[audio_pos + i], -1.0f, 1.0f);
        if (m.audio->sample_fmt == AV_SAMPLE_FMT_S16) {
          reinterpret_cast<int16_t*>(a->data[0])[i] = static_cast<int16_t>(std::lround(s * 32767));
        } else if (m.audio->sample_fmt == AV_SAMPLE_FMT_S32) {
          reinterpret_cast<int32_t*>(a->data[0])[i] =
              static_cast<int32_t>(std::lround(s * 2147483000.0));
        } else {  // FLTP / FLT
          reinterpret_cast<float*>(a->data[0])[i] = s;
        }
      }
      a->pts = static_cast<int64_t>(audio_pos);
      audio_pos += n;
      ok = m.Encode(m.audio, m.audio_stream, a);
      av_frame_free(&a);
    }
  };
  std::vector<double> grey(static_cast<size_t>(v.width) * v.height, 0.0);
  for (int k = 0; k < v.frames && ok; ++k) {
    write_audio_until(static_cast<double>(k) / v.fps, false);
    av_frame_make_writable(frame);
    if (v.draw) v.draw(k, &grey);
    const double level = v.draw ? 0.0 : v.brightness(k);
    for (int y = 0; y < v.height; ++y) {
      uint8_t* row = frame->data[0] + y * frame->linesize[0];
      for (int x = 0; x < v.width; ++x) {
        const double value = v.draw ? grey[static_cast<size_t>(y) * v.width + x]
                                    : level + 20.0 * (((x / 8) + (y / 8)) % 2);
        row[x] = static_cast<uint8_t>(std::clamp(std::lround(value), 0L, 255L));
      }
    }
    frame->pts = k;
    ok = m.Encode(m.video, m.video_stream, frame);
  }
  write_audio_until(0, true);
  av_frame_free(&frame);
  if (ok) ok = m.Encode(m.video, m.video_stream, nullptr);
  if (ok && m.audio != nullptr) ok = m.Encode(m.audio, m.audio_stream, nullptr);
  if (!ok) return fail("encoding failed");
  if (av_write_trailer(m.format) < 0) return fail("cannot write trailer");
  return Status::Ok();
}

}  // namespace arco::media::testing
