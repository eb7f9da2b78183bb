// Decoded video frames and images: one owned, tightly packed 8-bit buffer.
//
// Why this shape: detection, tracking and the sync signals only need 8-bit pixels, and
// a plain struct with a std::vector is easy to hand to any consumer (wrap as
// cv::Mat(height, width, CV_8UC3, pixels.data()) without a copy, or to numpy as an
// (height, width, 3) uint8 array). Colour is RGB order (what numpy/PIL and most
// detection models expect; OpenCV users convert with cv::COLOR_RGB2BGR). Gray is
// luma only, for cheap motion and flash signals.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace arco::media {

enum class PixelFormat {
  kRgb8,   // 3 bytes per pixel: R, G, B
  kGray8,  // 1 byte per pixel: luma
};

int ChannelCount(PixelFormat format);
const char* PixelFormatName(PixelFormat format);  // "rgb8", "gray8"

struct Image {
  int width = 0, height = 0;
  PixelFormat format = PixelFormat::kRgb8;
  // Row-major, rows of width * channels bytes with no padding between rows.
  std::vector<uint8_t> pixels;

  int channels() const { return ChannelCount(format); }
  size_t row_bytes() const { return static_cast<size_t>(width) * channels(); }
  bool empty() const { return pixels.empty(); }
  uint8_t* row(int y) { return pixels.data() + static_cast<size_t>(y) * row_bytes(); }
  const uint8_t* row(int y) const { return pixels.data() + static_cast<size_t>(y) * row_bytes(); }
  // Channel `c` of pixel (x, y); no bounds checks (hot loops).
  uint8_t at(int x, int y, int c = 0) const {
    return pixels[static_cast<size_t>(y) * row_bytes() + static_cast<size_t>(x) * channels() + c];
  }
};

// A zero-filled image; throws std::invalid_argument on a negative size.
Image MakeImage(int width, int height, PixelFormat format);

// `image` turned clockwise by `degrees` (0, 90, 180 or 270; throws
// std::invalid_argument otherwise), as a player turns a video with that display
// rotation: a 90 turn maps pixel (x, y) to (height - 1 - y, x).
Image RotateClockwise(const Image& image, int degrees);

}  // namespace arco::media
