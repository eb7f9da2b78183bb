// FrameSource for files FFmpeg's libav* decode (videos, and single images).
#include "arco/media/frame_source.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/display.h>
#include <libswscale/swscale.h>
}

#include <cmath>
#include <cstring>
#include <vector>

namespace arco::media {
namespace {

struct FormatCloser {
  void operator()(AVFormatContext* f) const { avformat_close_input(&f); }
};
struct CodecFreer {
  void operator()(AVCodecContext* c) const { avcodec_free_context(&c); }
};
struct PacketFreer {
  void operator()(AVPacket* p) const { av_packet_free(&p); }
};
struct FrameFreer {
  void operator()(AVFrame* f) const { av_frame_free(&f); }
};
struct SwsFreer {
  void operator()(SwsContext* s) const { sws_freeContext(s); }
};
using FormatPtr = std::unique_ptr<AVFormatContext, FormatCloser>;

// Forward seeks of at most this many frames decode forward instead of seeking the
// container (cheaper than going back to a key frame for the usual GOP sizes).
constexpr int64_t kDecodeForwardFrames = 16;

struct Demuxer {
  FormatPtr format;
  int stream_index = -1;
  const AVCodec* decoder = nullptr;
};

StatusOr<Demuxer> OpenDemuxer(const std::string& path) {
  // libav logs to stderr by default; every failure is returned as a Status instead.
  av_log_set_level(AV_LOG_QUIET);
  AVFormatContext* raw = nullptr;
  if (avformat_open_input(&raw, path.c_str(), nullptr, nullptr) < 0) {
    return Status::Error(path + ": cannot open video");
  }
  Demuxer d;
  d.format.reset(raw);
  if (avformat_find_stream_info(raw, nullptr) < 0) {
    return Status::Error(path + ": cannot read stream info");
  }
  d.stream_index = av_find_best_stream(raw, AVMEDIA_TYPE_VIDEO, -1, -1, &d.decoder, 0);
  if (d.stream_index < 0 || d.decoder == nullptr) {
    return Status::Error(path + (d.stream_index == AVERROR_STREAM_NOT_FOUND
                                     ? ": no video stream"
                                     : ": unsupported video codec"));
  }
  return d;
}

StatusOr<int64_t> CountPackets(const std::string& path) {
  ARCO_ASSIGN_OR_RETURN(Demuxer d, OpenDemuxer(path));
  std::unique_ptr<AVPacket, PacketFreer> packet(av_packet_alloc());
  int64_t count = 0;
  while (av_read_frame(d.format.get(), packet.get()) >= 0) {
    if (packet->stream_index == d.stream_index) ++count;
    av_packet_unref(packet.get());
  }
  return count;
}

// Clockwise display rotation from the display matrix (libav gives counter-clockwise).
int RotationDegrees(const AVStream* stream) {
  size_t size = 0;
  const uint8_t* data = av_stream_get_side_data(stream, AV_PKT_DATA_DISPLAYMATRIX, &size);
  if (data == nullptr || size < 9 * sizeof(int32_t)) return 0;
  const double counter_clockwise_deg =
      av_display_rotation_get(reinterpret_cast<const int32_t*>(data));
  if (!std::isfinite(counter_clockwise_deg)) return 0;
  const long quarter_turns = std::lround(-counter_clockwise_deg / 90.0);
  return static_cast<int>(((quarter_turns % 4) + 4) % 4) * 90;
}

class VideoFile : public FrameSource {
 public:
  VideoFile(std::string path, const VideoReaderOptions& options)
      : path_(std::move(path)), options_(options) {}

  Status Open(bool count_frames) {
    ARCO_RETURN_IF_ERROR(OpenDecoder());
    const AVStream* stream = format_->streams[stream_index_];
    VideoProperties& p = properties_;
    p.path = path_;
    p.codec = codec_->codec->name;
    const AVRational rate =
        av_guess_frame_rate(format_.get(), format_->streams[stream_index_], nullptr);
    if (rate.num > 0 && rate.den > 0) p.fps = Rational{rate.num, rate.den};
    p.fps_hz = p.fps.ToDouble();
    p.rotation_deg = RotationDegrees(stream);
    if (stream->nb_frames > 0) {
      p.frame_count = stream->nb_frames;
      p.frame_count_source = FrameCountSource::kContainer;
    } else if (count_frames) {
      ARCO_ASSIGN_OR_RETURN(p.frame_count, CountPackets(path_));
      p.frame_count_source = FrameCountSource::kCountedPackets;
    }
    p.duration_s = p.fps_hz > 0 ? static_cast<double>(p.frame_count) / p.fps_hz : 0.0;
    // The first frame gives the decoded size and the timestamp of frame 0.
    ARCO_ASSIGN_OR_RETURN(const bool got, Decode());
    if (!got) return Status::Error(path_ + ": no decodable video frames");
    if (frame_->width <= 0 || frame_->height <= 0) {
      return Status::Error(path_ + ": invalid frame size");
    }
    have_frame_ = true;
    first_pts_ = frame_->best_effort_timestamp;
    p.coded_width = frame_->width;
    p.coded_height = frame_->height;
    ScaledSize(p.coded_width, p.coded_height, options_.max_width, &p.width, &p.height);
    return Status::Ok();
  }

  StatusOr<bool> Read(Image* image) override { return Advance(image); }

  Status Seek(int64_t index) override {
    ARCO_RETURN_IF_ERROR(CheckIndex(index));
    if (index == next_frame_) return Status::Ok();
    if (index > next_frame_ && index - next_frame_ <= kDecodeForwardFrames) {
      return DecodeForwardTo(index);
    }
    ARCO_ASSIGN_OR_RETURN(const bool found, SeekByTimestamp(index));
    if (found) return Status::Ok();
    // Timestamps missing or off the frame grid: count from the start.
    ARCO_RETURN_IF_ERROR(OpenDecoder());
    next_frame_ = 0;
    return DecodeForwardTo(index);
  }

 private:
  // (Re)opens the file at its start.
  Status OpenDecoder() {
    codec_.reset();
    format_.reset();
    ARCO_ASSIGN_OR_RETURN(Demuxer d, OpenDemuxer(path_));
    format_ = std::move(d.format);
    stream_index_ = d.stream_index;
    const AVStream* stream = format_->streams[stream_index_];
    time_base_ = stream->time_base;
    frame_rate_ = av_guess_frame_rate(format_.get(), format_->streams[stream_index_], nullptr);
    codec_.reset(avcodec_alloc_context3(d.decoder));
    if (codec_ == nullptr || avcodec_parameters_to_context(codec_.get(), stream->codecpar) < 0) {
      return Status::Error(path_ + ": cannot set up the decoder");
    }
    codec_->thread_count = options_.decoder_threads;
    if (avcodec_open2(codec_.get(), d.decoder, nullptr) < 0) {
      return Status::Error(path_ + ": cannot open decoder");
    }
    if (packet_ == nullptr) packet_.reset(av_packet_alloc());
    if (frame_ == nullptr) frame_.reset(av_frame_alloc());
    if (shown_ == nullptr) shown_.reset(av_frame_alloc());
    av_frame_unref(shown_.get());
    draining_ = false;
    have_frame_ = false;
    return Status::Ok();
  }

  // Decodes the next frame into frame_; false at the end of the stream.
  StatusOr<bool> Decode() {
    while (true) {
      const int rc = avcodec_receive_frame(codec_.get(), frame_.get());
      if (rc >= 0) return true;
      if (rc == AVERROR_EOF || (rc == AVERROR(EAGAIN) && draining_)) return false;
      if (rc != AVERROR(EAGAIN)) {
        return Status::Error(path_ + ": cannot decode the frame after frame " +
                             std::to_string(next_frame_ - 1));
      }
      if (av_read_frame(format_.get(), packet_.get()) < 0) {
        draining_ = true;
        avcodec_send_packet(codec_.get(), nullptr);
      } else {
        // A damaged packet is rejected here and the decoder resynchronises on the
        // next one, as players do. An empty packet (AVI's dropped frame) is skipped:
        // sent, it would read as the end of the stream; the timeline repeats the
        // previous picture instead (Advance).
        if (packet_->stream_index == stream_index_ && packet_->size > 0) {
          avcodec_send_packet(codec_.get(), packet_.get());
        }
        av_packet_unref(packet_.get());
      }
    }
  }

  // One step along the frame timeline: the picture shown at frame next_frame_ goes
  // to *image (when given). Frame n shows the last decoded frame whose timestamp
  // rounds to at most n on the grid first_pts + n / fps, as a constant-frame-rate
  // player does: a gap in the timestamps (a dropped frame, a variable-rate AVI)
  // repeats the previous picture, a second frame in one tick is dropped. Frames
  // without timestamps are taken in decoding order. False after the last frame.
  StatusOr<bool> Advance(Image* image) {
    while (true) {
      if (!have_frame_) {
        ARCO_ASSIGN_OR_RETURN(const bool got, Decode());
        if (!got) return false;
        have_frame_ = true;
      }
      const bool have_shown = shown_->buf[0] != nullptr;
      const int64_t at = IndexOfPts(frame_->best_effort_timestamp);
      if (have_shown && at >= 0 && at < next_frame_) {  // a second frame in one tick
        av_frame_unref(frame_.get());
        have_frame_ = false;
        continue;
      }
      if (!have_shown || at < 0 || at <= next_frame_) {  // frame_ is frame next_frame_
        av_frame_unref(shown_.get());
        av_frame_move_ref(shown_.get(), frame_.get());
        have_frame_ = false;
      }
      if (image != nullptr) ARCO_RETURN_IF_ERROR(Convert(*shown_, image));
      ++next_frame_;
      return true;
    }
  }

  // Steps along the timeline until the next Read returns frame `index`.
  Status DecodeForwardTo(int64_t index) {
    while (next_frame_ < index) {
      ARCO_ASSIGN_OR_RETURN(const bool more, Advance(nullptr));
      if (!more) {
        return Status::Error(path_ + ": frame " + std::to_string(index) +
                             " not found (the video ends after " + std::to_string(next_frame_) +
                             " frames)");
      }
    }
    return Status::Ok();
  }

  // Nearest frame index of a timestamp on the grid first_pts + n / fps; -1 when
  // there is no timestamp or no frame rate.
  int64_t IndexOfPts(int64_t pts) const {
    if (pts == AV_NOPTS_VALUE || first_pts_ == AV_NOPTS_VALUE || frame_rate_.num <= 0 ||
        frame_rate_.den <= 0) {
      return -1;
    }
    return av_rescale_q_rnd(pts - first_pts_,
                            time_base_,
                            av_inv_q(frame_rate_),
                            static_cast<AVRounding>(AV_ROUND_NEAR_INF | AV_ROUND_PASS_MINMAX));
  }

  // Seeks the container to the key frame before frame `index`, decodes forward and
  // checks timestamps (the frame shown at `index` is the last one whose timestamp
  // rounds to at most `index`). False when that cannot find the frame (the caller counts
  // from the start instead).
  StatusOr<bool> SeekByTimestamp(int64_t index) {
    if (first_pts_ == AV_NOPTS_VALUE || frame_rate_.num <= 0 || frame_rate_.den <= 0) return false;
    const int64_t target = first_pts_ + av_rescale_q(index, av_inv_q(frame_rate_), time_base_);
    // A demuxer may land on a key frame after the target: aim 1, 2, 4 s earlier.
    for (int attempt = 0; attempt < 4; ++attempt) {
      const int64_t back_s = attempt == 0 ? 0 : (int64_t{1} << (attempt - 1));
      const int64_t seek_ts = target - av_rescale_q(back_s, AVRational{1, 1}, time_base_);
      if (av_seek_frame(format_.get(), stream_index_, seek_ts, AVSEEK_FLAG_BACKWARD) < 0) {
        return false;
      }
      avcodec_flush_buffers(codec_.get());
      draining_ = false;
      have_frame_ = false;
      av_frame_unref(shown_.get());
      while (true) {
        ARCO_ASSIGN_OR_RETURN(const bool got, Decode());
        if (!got) return false;
        const int64_t at = IndexOfPts(frame_->best_effort_timestamp);
        if (at < 0) return false;
        if (at < index) {  // shown at `index` unless a later frame is
          av_frame_unref(shown_.get());
          av_frame_move_ref(shown_.get(), frame_.get());
          continue;
        }
        if (at == index || shown_->buf[0] != nullptr) {
          // Advance shows frame_ at `index`, or repeats shown_ until frame_'s tick.
          have_frame_ = true;
          next_frame_ = index;
          return true;
        }
        av_frame_unref(frame_.get());
        break;  // landed after the target: aim earlier
      }
      if (seek_ts <= first_pts_) return false;
    }
    return false;
  }

  // `frame` -> *image in the requested format and size.
  Status Convert(const AVFrame& frame, Image* image) {
    const VideoProperties& p = properties_;
    const bool rgb = options_.format == PixelFormat::kRgb8;
    sws_.reset(sws_getCachedContext(sws_.release(),
                                    frame.width,
                                    frame.height,
                                    static_cast<AVPixelFormat>(frame.format),
                                    p.width,
                                    p.height,
                                    rgb ? AV_PIX_FMT_RGB24 : AV_PIX_FMT_GRAY8,
                                    SWS_AREA,
                                    nullptr,
                                    nullptr,
                                    nullptr));
    if (sws_ == nullptr) return Status::Error(path_ + ": unsupported pixel format");
    if (image->width != p.width || image->height != p.height || image->format != options_.format ||
        image->pixels.size() !=
            static_cast<size_t>(p.width) * p.height * ChannelCount(options_.format)) {
      *image = MakeImage(p.width, p.height, options_.format);
    }
    // swscale's SIMD paths may write a few bytes past the end of a tightly packed
    // row (seen with 2300 px wide JPEGs: 4 bytes past the last row), so convert into a
    // padded buffer and copy the rows out.
    const size_t row_bytes = image->row_bytes();
    const size_t stride = (row_bytes + 63) / 64 * 64;
    converted_.resize(stride * (p.height + 1));
    uint8_t* planes[1] = {converted_.data()};
    int strides[1] = {static_cast<int>(stride)};
    sws_scale(sws_.get(), frame.data, frame.linesize, 0, frame.height, planes, strides);
    for (int y = 0; y < p.height; ++y) {
      std::memcpy(image->row(y), converted_.data() + y * stride, row_bytes);
    }
    return Status::Ok();
  }

  std::string path_;
  VideoReaderOptions options_;
  FormatPtr format_;
  std::unique_ptr<AVCodecContext, CodecFreer> codec_;
  std::unique_ptr<AVPacket, PacketFreer> packet_;
  std::unique_ptr<AVFrame, FrameFreer> frame_;  // decoded, not yet shown (have_frame_)
  std::unique_ptr<AVFrame, FrameFreer> shown_;  // the picture of frame next_frame_ - 1
  std::unique_ptr<SwsContext, SwsFreer> sws_;
  std::vector<uint8_t> converted_;  // swscale's output, padded rows (see Convert)
  int stream_index_ = -1;
  AVRational time_base_{1, 1};
  AVRational frame_rate_{0, 1};
  int64_t first_pts_ = AV_NOPTS_VALUE;
  bool draining_ = false;
  bool have_frame_ = false;
};

}  // namespace

StatusOr<std::unique_ptr<FrameSource>> OpenVideoFile(const std::string& path,
                                                     const VideoReaderOptions& options,
                                                     bool count_frames) {
  auto file = std::make_unique<VideoFile>(path, options);
  ARCO_RETURN_IF_ERROR(file->Open(count_frames));
  return std::unique_ptr<FrameSource>(std::move(file));
}

}  // namespace arco::media
