#include "arco/media/image.h"

#include <algorithm>
#include <cstddef>
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
  const auto in_row = static_cast<ptrdiff_t>(image.row_bytes());
  const auto out_row = static_cast<ptrdiff_t>(out.row_bytes());
  // In square tiles: a 90/270 degree turn reads rows and writes columns, and a tile keeps
  // both in the cache (a whole-row loop misses on every written pixel of a large frame).
  constexpr int kTile = 64;
  for (int y0 = 0; y0 < h; y0 += kTile) {
    const int y1 = std::min(h, y0 + kTile);
    for (int x0 = 0; x0 < w; x0 += kTile) {
      const int x1 = std::min(w, x0 + kTile);
      for (int y = y0; y < y1; ++y) {
        // Source pixel (x, y) lands at (h-1-y, x) for 90, (w-1-x, h-1-y) for 180 and
        // (y, w-1-x) for 270: along a source row, the target moves by a fixed step.
        ptrdiff_t start = 0, step = 0;
        if (degrees == 90) {
          start = x0 * out_row + static_cast<ptrdiff_t>(h - 1 - y) * c;
          step = out_row;
        } else if (degrees == 180) {
          start = (h - 1 - y) * out_row + static_cast<ptrdiff_t>(w - 1 - x0) * c;
          step = -c;
        } else {  // 270
          start = (w - 1 - x0) * out_row + static_cast<ptrdiff_t>(y) * c;
          step = -out_row;
        }
        const uint8_t* from = image.pixels.data() + y * in_row + static_cast<ptrdiff_t>(x0) * c;
        uint8_t* dst = out.pixels.data() + start;
        if (c == 3) {
          for (int x = x0; x < x1; ++x, from += 3, dst += step) {
            dst[0] = from[0];
            dst[1] = from[1];
            dst[2] = from[2];
          }
        } else {
          for (int x = x0; x < x1; ++x, from += c, dst += step) {
            for (int k = 0; k < c; ++k) dst[k] = from[k];
          }
        }
      }
    }
  }
  return out;
}

}  // namespace arco::media
