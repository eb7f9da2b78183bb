#include "arco/media/video_writer.h"

#include <algorithm>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/display.h>
#include <libavutil/log.h>
#include <libavutil/opt.h>
#include <libavutil/pixdesc.h>
#include <libswscale/swscale.h>
}

#include <cstring>
#include <utility>
#include <vector>

#include "arco/media/av_error.h"

namespace arco::media {

Status VideoWriterOptions::Validate() const {
  if (width < 1 || height < 1 || width > 16384 || height > 16384) {
    return Status::Error("VideoWriterOptions: width and height must be in [1, 16384], got " +
                         std::to_string(width) + "x" + std::to_string(height));
  }
  if (fps.num <= 0 || fps.den <= 0) {
    return Status::Error("VideoWriterOptions: fps must be a positive fraction, got " +
                         std::to_string(fps.num) + "/" + std::to_string(fps.den));
  }
  if (rotation_deg != 0 && rotation_deg != 90 && rotation_deg != 180 && rotation_deg != 270) {
    return Status::Error("VideoWriterOptions: rotation_deg must be 0, 90, 180 or 270, got " +
                         std::to_string(rotation_deg));
  }
  if (gop < 1) return Status::Error("VideoWriterOptions: gop must be >= 1");
  if (b_frames < 0 || b_frames > 16) {
    return Status::Error("VideoWriterOptions: b_frames must be in [0, 16]");
  }
  if (bit_rate < 0) return Status::Error("VideoWriterOptions: bit_rate must be >= 0");
  if (threads < 1 || threads > 64) {
    return Status::Error("VideoWriterOptions: threads must be in [1, 64]");
  }
  if (codec.empty()) return Status::Error("VideoWriterOptions: codec is empty");
  return Status::Ok();
}

struct VideoWriter::State {
  std::string path;
  VideoWriterOptions options;
  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  AVStream* stream = nullptr;
  AVPacket* packet = nullptr;
  AVFrame* frame = nullptr;
  SwsContext* sws = nullptr;
  std::vector<uint8_t> padded;  // the frame being converted, padded rows (see Write)
  PixelFormat sws_source = PixelFormat::kRgb8;
  bool header_written = false;
  bool closed = false;
  Status error = Status::Ok();  // the first failure; sticky
  int64_t frames = 0;

  ~State() {
    sws_freeContext(sws);
    av_frame_free(&frame);
    av_packet_free(&packet);
    avcodec_free_context(&codec);
    if (format != nullptr) {
      if (format->pb != nullptr && !(format->oformat->flags & AVFMT_NOFILE)) {
        avio_closep(&format->pb);
      }
      avformat_free_context(format);
    }
  }

  Status Fail(const std::string& what, int code = 0) {
    std::string message = path + ": " + what;
    if (code < 0) message += ": " + AvError(code);
    if (error.ok()) error = Status::Error(message);
    return Status::Error(message);
  }

  // Sends `f` (nullptr flushes) and writes every packet the encoder returns.
  Status Send(AVFrame* f) {
    int rc = avcodec_send_frame(codec, f);
    if (rc < 0) return Fail("encoding failed", rc);
    while (true) {
      rc = avcodec_receive_packet(codec, packet);
      if (rc == AVERROR(EAGAIN) || rc == AVERROR_EOF) return Status::Ok();
      if (rc < 0) return Fail("encoding failed", rc);
      av_packet_rescale_ts(packet, codec->time_base, stream->time_base);
      packet->stream_index = stream->index;
      rc = av_interleaved_write_frame(format, packet);
      if (rc < 0) return Fail("cannot write a packet", rc);
    }
  }

  Status Finish() {
    if (!header_written) return error.ok() ? Fail("not opened") : error;
    Status flushed = Send(nullptr);
    const int rc = av_write_trailer(format);
    if (flushed.ok() && rc < 0) flushed = Fail("cannot write the trailer", rc);
    if (format->pb != nullptr && !(format->oformat->flags & AVFMT_NOFILE)) {
      const int close_rc = avio_closep(&format->pb);
      if (flushed.ok() && close_rc < 0) flushed = Fail("cannot close the file", close_rc);
    }
    return flushed;
  }
};

StatusOr<VideoWriter> VideoWriter::Open(const std::string& path,
                                        const VideoWriterOptions& options) {
  // libav (and libx264 through it) logs to stderr by default; every failure is returned
  // as a Status instead (as the reader does, video_file.cc).
  av_log_set_level(AV_LOG_QUIET);
  if (Status valid = options.Validate(); !valid.ok()) {
    return Status::Error(path + ": " + valid.message());
  }
  auto s = std::make_unique<State>();
  s->path = path;
  s->options = options;
  int rc = avformat_alloc_output_context2(
      &s->format,
      nullptr,
      options.container.empty() ? nullptr : options.container.c_str(),
      path.c_str());
  if (rc < 0 || s->format == nullptr) {
    return s->Fail(
        "cannot create a " + (options.container.empty() ? std::string("muxer for this file name")
                                                        : "'" + options.container + "' muxer"),
        rc);
  }
  const AVCodec* encoder = avcodec_find_encoder_by_name(options.codec.c_str());
  if (encoder == nullptr || encoder->type != AVMEDIA_TYPE_VIDEO) {
    return s->Fail("this FFmpeg has no video encoder '" + options.codec + "'");
  }

  // The stored pixel format.
  AVPixelFormat pix_fmt = AV_PIX_FMT_YUV420P;
  if (!options.pixel_format.empty()) {
    pix_fmt = av_get_pix_fmt(options.pixel_format.c_str());
    if (pix_fmt == AV_PIX_FMT_NONE) return s->Fail("unknown pixel format " + options.pixel_format);
  } else if (encoder->id == AV_CODEC_ID_FFV1) {
    // FFV1's lossless RGB: 8-bit RGB in 32-bit words (bgr0 on little-endian machines).
    pix_fmt = options.source_format == PixelFormat::kGray8 ? AV_PIX_FMT_GRAY8 : AV_PIX_FMT_0RGB32;
  }
  if (encoder->pix_fmts != nullptr) {
    bool supported = false;
    for (const AVPixelFormat* p = encoder->pix_fmts; *p != AV_PIX_FMT_NONE; ++p) {
      supported = supported || *p == pix_fmt;
    }
    if (!supported) {
      return s->Fail(options.codec + " cannot store pixel format " + av_get_pix_fmt_name(pix_fmt));
    }
  }
  const AVPixFmtDescriptor* desc = av_pix_fmt_desc_get(pix_fmt);
  const int x_step = 1 << desc->log2_chroma_w, y_step = 1 << desc->log2_chroma_h;
  if (options.width % x_step != 0 || options.height % y_step != 0) {
    return s->Fail(std::to_string(options.width) + "x" + std::to_string(options.height) +
                   " cannot be stored as " + av_get_pix_fmt_name(pix_fmt) +
                   " (width a multiple of " + std::to_string(x_step) + ", height of " +
                   std::to_string(y_step) + ")");
  }

  s->codec = avcodec_alloc_context3(encoder);
  s->packet = av_packet_alloc();
  s->frame = av_frame_alloc();
  if (s->codec == nullptr || s->packet == nullptr || s->frame == nullptr) {
    return s->Fail("out of memory");
  }
  AVCodecContext* c = s->codec;
  c->width = options.width;
  c->height = options.height;
  c->pix_fmt = pix_fmt;
  c->time_base = AVRational{options.fps.den, options.fps.num};
  c->framerate = AVRational{options.fps.num, options.fps.den};
  c->gop_size = options.gop;
  c->max_b_frames = options.b_frames;
  c->thread_count = options.threads;
  if (options.bit_rate > 0) {
    c->bit_rate = options.bit_rate;
  } else if (encoder->id == AV_CODEC_ID_MPEG4) {
    c->flags |= AV_CODEC_FLAG_QSCALE;
    c->global_quality = FF_QP2LAMBDA * 2;
  } else if (options.codec == "libx264") {
    av_opt_set(c->priv_data, "crf", "16", 0);
  } else if (encoder->id == AV_CODEC_ID_VP8 || encoder->id == AV_CODEC_ID_VP9) {
    // libvpx's constrained quality: crf 16 (0-63, lower is better) under a cap of 0.12
    // bit per pixel (5.5 Mbit/s at 1150x1328, 30 fps), which libvpx needs (VP8 has no
    // unconstrained quality mode); "realtime" with the fastest speed, as a web page's
    // preview is written per take. The speed is negative: libvpx's VP8 treats a positive
    // cpu-used in realtime mode as a starting point and re-selects the speed from how
    // long each frame took to encode (vp8_auto_select_speed), so a loaded machine wrote
    // different bytes; a negative value fixes the speed at its magnitude (VP9 takes the
    // magnitude too).
    c->bit_rate = std::max<int64_t>(
        500000,
        static_cast<int64_t>(0.12 * options.width * options.height * options.fps.ToDouble()));
    av_opt_set(c->priv_data, "crf", "16", 0);
    av_opt_set(c->priv_data, "deadline", "realtime", 0);
    av_opt_set(c->priv_data, "cpu-used", "-8", 0);
  }
  if (s->format->oformat->flags & AVFMT_GLOBALHEADER) c->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  if (options.bitexact) {
    c->flags |= AV_CODEC_FLAG_BITEXACT;
    s->format->flags |= AVFMT_FLAG_BITEXACT;
  }
  rc = avcodec_open2(c, encoder, nullptr);
  if (rc < 0) return s->Fail("cannot open the " + options.codec + " encoder", rc);

  s->stream = avformat_new_stream(s->format, nullptr);
  if (s->stream == nullptr) return s->Fail("out of memory");
  rc = avcodec_parameters_from_context(s->stream->codecpar, c);
  if (rc < 0) return s->Fail("cannot set the stream parameters", rc);
  s->stream->time_base = c->time_base;
  s->stream->avg_frame_rate = c->framerate;
  if (options.rotation_deg != 0) {
    // Only the QuickTime family stores a display matrix (FFmpeg 5's Matroska muxer
    // drops it): refuse rather than lose it silently.
    const std::string muxer = s->format->oformat->name;
    if (muxer != "mov" && muxer != "mp4" && muxer != "3gp" && muxer != "3g2" && muxer != "ipod") {
      return s->Fail("the " + muxer +
                     " muxer cannot store a display rotation (use mp4 or mov, e.g. ffv1 in mov)");
    }
    uint8_t* matrix =
        av_stream_new_side_data(s->stream, AV_PKT_DATA_DISPLAYMATRIX, 9 * sizeof(int32_t));
    if (matrix == nullptr) return s->Fail("cannot add a display matrix");
    // av_display_rotation_set takes the counter-clockwise angle; VideoReader reports
    // the clockwise one (as players apply it), so the two round-trip.
    av_display_rotation_set(reinterpret_cast<int32_t*>(matrix), options.rotation_deg);
  }
  if (!(s->format->oformat->flags & AVFMT_NOFILE)) {
    rc = avio_open(&s->format->pb, path.c_str(), AVIO_FLAG_WRITE);
    if (rc < 0) return s->Fail("cannot create the file", rc);
  }
  AVDictionary* muxer_options = nullptr;
  if (std::string(s->format->oformat->name) == "image2") {
    av_dict_set(&muxer_options, "update", "1", 0);  // the literal file name, not a pattern
  }
  rc = avformat_write_header(s->format, &muxer_options);
  av_dict_free(&muxer_options);
  if (rc < 0) return s->Fail("cannot write the header", rc);
  s->header_written = true;

  s->frame->format = pix_fmt;
  s->frame->width = options.width;
  s->frame->height = options.height;
  rc = av_frame_get_buffer(s->frame, 0);
  if (rc < 0) return s->Fail("cannot allocate a frame", rc);
  return VideoWriter(std::move(s));
}

VideoWriter::VideoWriter(std::unique_ptr<State> state) : state_(std::move(state)) {}
VideoWriter::VideoWriter(VideoWriter&&) noexcept = default;
VideoWriter& VideoWriter::operator=(VideoWriter&& other) noexcept {
  if (this != &other) {
    if (state_ != nullptr) (void)Close();
    state_ = std::move(other.state_);
  }
  return *this;
}
VideoWriter::~VideoWriter() {
  if (state_ != nullptr) (void)Close();
}

Status VideoWriter::Write(const Image& image) {
  State& s = *state_;
  if (s.closed) return Status::Error(s.path + ": write after Close");
  if (!s.error.ok()) return s.error;
  if (image.width != s.options.width || image.height != s.options.height ||
      image.pixels.size() != static_cast<size_t>(image.width) * image.height * image.channels()) {
    return s.Fail("frame " + std::to_string(s.frames) + " is " + std::to_string(image.width) + "x" +
                  std::to_string(image.height) + ", the video " + std::to_string(s.options.width) +
                  "x" + std::to_string(s.options.height));
  }
  if (s.sws == nullptr || s.sws_source != image.format) {
    sws_freeContext(s.sws);
    // Same size: swscale's unscaled converters (exact for RGB24 <-> 0RGB32 and
    // gray -> gray); accurate rounding for the YUV conversions.
    s.sws = sws_getContext(image.width,
                           image.height,
                           image.format == PixelFormat::kRgb8 ? AV_PIX_FMT_RGB24 : AV_PIX_FMT_GRAY8,
                           s.options.width,
                           s.options.height,
                           s.codec->pix_fmt,
                           SWS_BICUBIC | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT,
                           nullptr,
                           nullptr,
                           nullptr);
    if (s.sws == nullptr) return s.Fail("cannot convert the frames to the stored pixel format");
    s.sws_source = image.format;
  }
  int rc = av_frame_make_writable(s.frame);
  if (rc < 0) return s.Fail("cannot allocate a frame", rc);
  // swscale's SIMD paths read up to 16 bytes past a tightly packed row (valgrind):
  // hand it padded rows.
  const size_t row_bytes = image.row_bytes();
  const size_t stride = (row_bytes + 63) / 64 * 64;
  s.padded.resize(stride * (image.height + 1));
  for (int y = 0; y < image.height; ++y) {
    std::memcpy(s.padded.data() + y * stride, image.row(y), row_bytes);
  }
  const uint8_t* planes[1] = {s.padded.data()};
  const int strides[1] = {static_cast<int>(stride)};
  sws_scale(s.sws, planes, strides, 0, image.height, s.frame->data, s.frame->linesize);
  s.frame->pts = s.frames;
  ARCO_RETURN_IF_ERROR(s.Send(s.frame));
  ++s.frames;
  return Status::Ok();
}

Status VideoWriter::Close() {
  State& s = *state_;
  if (s.closed) return s.error;
  s.closed = true;
  if (!s.error.ok()) return s.error;
  return s.Finish();
}

int64_t VideoWriter::frames_written() const { return state_->frames; }
const std::string& VideoWriter::path() const { return state_->path; }

bool HasVideoEncoder(const std::string& name) {
  const AVCodec* codec = avcodec_find_encoder_by_name(name.c_str());
  return codec != nullptr && codec->type == AVMEDIA_TYPE_VIDEO;
}

unsigned CodecLibraryVersion() { return avcodec_version(); }

Status WriteImageFile(const std::string& path, const Image& image) {
  if (image.empty()) return Status::Error(path + ": empty image");
  VideoWriterOptions options;
  options.container = "image2";
  options.codec = "png";
  options.width = image.width;
  options.height = image.height;
  options.fps = Rational{1, 1};
  options.source_format = image.format;
  options.pixel_format = image.format == PixelFormat::kRgb8 ? "rgb24" : "gray";
  ARCO_ASSIGN_OR_RETURN(VideoWriter writer, VideoWriter::Open(path, options));
  ARCO_RETURN_IF_ERROR(writer.Write(image));
  return writer.Close();
}

}  // namespace arco::media
