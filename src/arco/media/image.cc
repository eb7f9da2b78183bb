#include "arco/media/image.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace arco::media {

int ChannelCount(PixelFormat format) { return format == PixelFormat::kRgb8 ? 3 : 1; }

const char* PixelFormatName(PixelFormat format) {
  return format == PixelFormat::kRgb8 ? "rgb8" : "gray8";
}

Image MakeImage(int width, int height, PixelFormat format) {
  if (width < 0 || height < 0) {
    throw std::invalid_argument("MakeImage: negative size " + std::to_string(width) + "x" +
                                std::to_string(height));
  }
  Image image;
  image.width = width;
  image.height = height;
  image.format = format;
  image.pixels.assign(image.row_bytes() * static_cast<size_t>(height), 0);
  return image;
}

Image RotateClockwise(const Image& image, int degrees) {
  if (degrees != 0 && degrees != 90 && degrees != 180 && degrees != 270) {
    throw std::invalid_argument("RotateClockwise: " + std::to_string(degrees) +
                                " is not 0, 90, 180 or 270");
  }
  if (degrees == 0) return image;
  const bool swap = degrees != 180;
  Image out =
      MakeImage(swap ? image.height : image.width, swap ? image.width : image.height, image.format);
  const int c = image.channels();
  const int w = image.width, h = image.height;
  const size_t in_row = image.row_bytes(), out_row = out.row_bytes();
  // In square tiles: a 90/270 degree turn reads rows and writes columns, and a tile keeps
  // both in the cache (a whole-row loop misses on every written pixel of a large frame).
  constexpr int kTile = 64;
  for (int y0 = 0; y0 < h; y0 += kTile) {
    const int y1 = std::min(h, y0 + kTile);
    for (int x0 = 0; x0 < w; x0 += kTile) {
      const int x1 = std::min(w, x0 + kTile);
      for (int y = y0; y < y1; ++y) {
        const uint8_t* src = image.pixels.data() + static_cast<size_t>(y) * in_row;
        for (int x = x0; x < x1; ++x) {
          // Where source pixel (x, y) lands in the turned image.
          int ox = x, oy = y;
          if (degrees == 90) {
            ox = h - 1 - y;
            oy = x;
          } else if (degrees == 180) {
            ox = w - 1 - x;
            oy = h - 1 - y;
          } else {  // 270
            ox = y;
            oy = w - 1 - x;
          }
          uint8_t* dst =
              out.pixels.data() + static_cast<size_t>(oy) * out_row + static_cast<size_t>(ox) * c;
          const uint8_t* from = src + static_cast<size_t>(x) * c;
          for (int k = 0; k < c; ++k) dst[k] = from[k];
        }
      }
    }
  }
  return out;
}

}  // namespace arco::media
