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

}  // namespace arco::media
