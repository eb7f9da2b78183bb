#include "arco/media/test_video.h"

#include <string>

#include "arco/media/video_writer.h"

namespace arco::media::testing {
namespace {

constexpr int kBlock = 32;
constexpr uint8_t kDark = 40, kBright = 215;

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

bool HasEncoder(const std::string& name) { return HasVideoEncoder(name); }

Status WriteIndexVideo(const std::string& path, const IndexVideo& v) {
  return WriteGrayVideo(path, v, [&](int k) { return IndexFrame(v, k); });
}

Status WriteGrayVideo(const std::string& path,
                      const IndexVideo& v,
                      const std::function<Image(int)>& make_frame) {
  VideoWriterOptions options;
  options.container = v.container;
  options.codec = v.codec;
  options.width = v.width;
  options.height = v.height;
  options.fps = v.fps;
  options.gop = v.gop;
  options.b_frames = v.b_frames;
  options.rotation_deg = v.rotation_deg;
  options.source_format = PixelFormat::kGray8;
  options.pixel_format = "yuv420p";
  options.bit_rate = 4000000;
  ARCO_ASSIGN_OR_RETURN(VideoWriter writer, VideoWriter::Open(path, options));
  for (int k = 0; k < v.frames; ++k) {
    const Image frame = make_frame(k);
    if (frame.width != v.width || frame.height != v.height || frame.format != PixelFormat::kGray8) {
      return Status::Error(path + ": frame " + std::to_string(k) + " is not a " +
                           std::to_string(v.width) + "x" + std::to_string(v.height) +
                           " gray image");
    }
    ARCO_RETURN_IF_ERROR(writer.Write(frame));
  }
  return writer.Close();
}

Status WriteIndexPng(const std::string& path, const IndexVideo& video, int k) {
  return WriteImageFile(path, IndexFrame(video, k));
}

}  // namespace arco::media::testing
