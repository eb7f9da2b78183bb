#include "arco/media/image.h"

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
  for (int y = 0; y < h; ++y) {
    const uint8_t* src = image.row(y);
    for (int x = 0; x < w; ++x) {
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
      uint8_t* dst = out.row(oy) + static_cast<size_t>(ox) * c;
      for (int k = 0; k < c; ++k) dst[k] = src[static_cast<size_t>(x) * c + k];
    }
  }
  return out;
}

}  // namespace arco::media
