#include "arco/media/test_video.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/display.h>
}

#include <cstdio>
#include <cstring>
#include <memory>

namespace arco::media::testing {
namespace {

constexpr int kBlock = 32;
constexpr uint8_t kDark = 40, kBright = 215;

struct Encoder {
  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  AVStream* stream = nullptr;
  AVPacket* packet = av_packet_alloc();
  ~Encoder() {
    av_packet_free(&packet);
    avcodec_free_context(&codec);
    if (format != nullptr) {
      if (format->pb != nullptr) avio_closep(&format->pb);
      avformat_free_context(format);
    }
  }
  bool Send(AVFrame* frame) {  // nullptr flushes
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

Image IndexFrame(const IndexVideo& video, int k) {
  Image image = MakeImage(video.width, video.height, PixelFormat::kGray8);
  const int columns = video.width / kBlock;
  for (int y = 0; y < video.height; ++y) {
    for (int x = 0; x < video.width; ++x) {
      const int bit = (y / kBlock) * columns + x / kBlock;
      image.row(y)[x] = (bit < 31 && ((k >> bit) & 1)) ? kBright : kDark;
    }
  }
  return image;
}

int ReadIndex(const Image& frame) {
  // Blocks scale with the frame; the bit count follows from the 32 px grid at the
  // frame's aspect, reading the centre of each block.
  const int columns = 4, rows = 3;  // 128 x 96 and its scaled versions
  if (frame.width < columns || frame.height < rows) return -1;
  int index = 0;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < columns; ++c) {
      const int x = (2 * c + 1) * frame.width / (2 * columns);
      const int y = (2 * r + 1) * frame.height / (2 * rows);
      int sum = 0;
      for (int ch = 0; ch < frame.channels(); ++ch) sum += frame.at(x, y, ch);
      const int level = sum / frame.channels();
      if (level > 170) {
        index |= 1 << (r * columns + c);
      } else if (level > 85) {
        return -1;  // neither dark nor bright: not an index frame
      }
    }
  }
  return index;
}

bool HasEncoder(const std::string& name) { return avcodec_find_encoder_by_name(name.c_str()); }

Status WriteIndexVideo(const std::string& path, const IndexVideo& v) {
  return WriteGrayVideo(path, v, [&](int k) { return IndexFrame(v, k); });
}

Status WriteGrayVideo(const std::string& path,
                      const IndexVideo& v,
                      const std::function<Image(int)>& make_frame) {
  auto fail = [&](const std::string& what) { return Status::Error(path + ": " + what); };
  Encoder e;
  if (avformat_alloc_output_context2(&e.format, nullptr, v.container.c_str(), path.c_str()) < 0) {
    return fail("cannot create the " + v.container + " muxer");
  }
  const AVCodec* encoder = avcodec_find_encoder_by_name(v.codec.c_str());
  if (encoder == nullptr) return fail("no " + v.codec + " encoder");
  e.codec = avcodec_alloc_context3(encoder);
  e.codec->width = v.width;
  e.codec->height = v.height;
  e.codec->pix_fmt = AV_PIX_FMT_YUV420P;
  e.codec->time_base = AVRational{v.fps.den, v.fps.num};
  e.codec->framerate = AVRational{v.fps.num, v.fps.den};
  e.codec->gop_size = v.gop;
  e.codec->max_b_frames = v.b_frames;
  e.codec->bit_rate = 4000000;
  e.codec->thread_count = 1;
  if (e.format->oformat->flags & AVFMT_GLOBALHEADER) e.codec->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  if (avcodec_open2(e.codec, encoder, nullptr) < 0) return fail("cannot open " + v.codec);
  e.stream = avformat_new_stream(e.format, nullptr);
  avcodec_parameters_from_context(e.stream->codecpar, e.codec);
  e.stream->time_base = e.codec->time_base;
  e.stream->avg_frame_rate = e.codec->framerate;
  if (v.rotation_deg != 0) {
    uint8_t* matrix =
        av_stream_new_side_data(e.stream, AV_PKT_DATA_DISPLAYMATRIX, 9 * sizeof(int32_t));
    if (matrix == nullptr) return fail("cannot add a display matrix");
    // av_display_rotation_set takes the clockwise angle (av_display_rotation_get
    // returns the counter-clockwise one).
    av_display_rotation_set(reinterpret_cast<int32_t*>(matrix), v.rotation_deg);
  }
  if (avio_open(&e.format->pb, path.c_str(), AVIO_FLAG_WRITE) < 0) return fail("cannot write");
  if (avformat_write_header(e.format, nullptr) < 0) return fail("cannot write the header");

  AVFrame* frame = av_frame_alloc();
  frame->format = AV_PIX_FMT_YUV420P;
  frame->width = v.width;
  frame->height = v.height;
  av_frame_get_buffer(frame, 0);
  bool ok = true;
  for (int k = 0; k < v.frames && ok; ++k) {
    av_frame_make_writable(frame);
    const Image luma = make_frame(k);
    if (luma.width != v.width || luma.height != v.height || luma.format != PixelFormat::kGray8) {
      ok = false;
      break;
    }
    for (int y = 0; y < v.height; ++y) {
      std::memcpy(frame->data[0] + y * frame->linesize[0], luma.row(y), v.width);
    }
    for (int plane = 1; plane < 3; ++plane) {
      for (int y = 0; y < v.height / 2; ++y) {
        std::memset(frame->data[plane] + y * frame->linesize[plane], 128, v.width / 2);
      }
    }
    frame->pts = k;
    ok = e.Send(frame);
  }
  av_frame_free(&frame);
  if (ok) ok = e.Send(nullptr);
  if (!ok) return fail("encoding failed");
  if (av_write_trailer(e.format) < 0) return fail("cannot write the trailer");
  return Status::Ok();
}

Status WriteIndexPng(const std::string& path, const IndexVideo& video, int k) {
  auto fail = [&](const std::string& what) { return Status::Error(path + ": " + what); };
  const AVCodec* png = avcodec_find_encoder(AV_CODEC_ID_PNG);
  if (png == nullptr) return fail("no PNG encoder");
  AVCodecContext* codec = avcodec_alloc_context3(png);
  std::unique_ptr<AVCodecContext, void (*)(AVCodecContext*)> codec_guard(
      codec, [](AVCodecContext* c) { avcodec_free_context(&c); });
  codec->width = video.width;
  codec->height = video.height;
  codec->pix_fmt = AV_PIX_FMT_GRAY8;
  codec->time_base = AVRational{1, 1};
  if (avcodec_open2(codec, png, nullptr) < 0) return fail("cannot open the PNG encoder");
  AVFrame* frame = av_frame_alloc();
  std::unique_ptr<AVFrame, void (*)(AVFrame*)> frame_guard(frame,
                                                           [](AVFrame* f) { av_frame_free(&f); });
  frame->format = AV_PIX_FMT_GRAY8;
  frame->width = video.width;
  frame->height = video.height;
  if (av_frame_get_buffer(frame, 0) < 0) return fail("out of memory");
  const Image luma = IndexFrame(video, k);
  for (int y = 0; y < video.height; ++y) {
    std::memcpy(frame->data[0] + y * frame->linesize[0], luma.row(y), video.width);
  }
  AVPacket* packet = av_packet_alloc();
  std::unique_ptr<AVPacket, void (*)(AVPacket*)> packet_guard(
      packet, [](AVPacket* p) { av_packet_free(&p); });
  if (avcodec_send_frame(codec, frame) < 0 || avcodec_receive_packet(codec, packet) < 0) {
    return fail("PNG encoding failed");
  }
  std::FILE* out = std::fopen(path.c_str(), "wb");
  if (out == nullptr) return fail("cannot write");
  const bool ok = std::fwrite(packet->data, 1, packet->size, out) == size_t(packet->size);
  return std::fclose(out) == 0 && ok ? Status::Ok() : fail("cannot write");
}

}  // namespace arco::media::testing
