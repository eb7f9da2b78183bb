#include "arco/media/image.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace arco::media {
namespace {

// A 3 x 2 RGB image whose pixel (x, y) holds (x, y, 7).
Image Numbered() {
  Image image = MakeImage(3, 2, PixelFormat::kRgb8);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) {
      image.row(y)[3 * x] = static_cast<uint8_t>(x);
      image.row(y)[3 * x + 1] = static_cast<uint8_t>(y);
      image.row(y)[3 * x + 2] = 7;
    }
  return image;
}

TEST(RotateClockwise, MovesEveryPixelWhereAPlayerShowsIt) {
  const Image src = Numbered();
  const Image r90 = RotateClockwise(src, 90);
  ASSERT_EQ(r90.width, 2);
  ASSERT_EQ(r90.height, 3);
  // Turning clockwise puts the bottom-left pixel (0, 1) at the top-left.
  EXPECT_EQ(r90.at(0, 0, 0), 0);
  EXPECT_EQ(r90.at(0, 0, 1), 1);
  // The top-left pixel (0, 0) goes to the top-right.
  EXPECT_EQ(r90.at(1, 0, 0), 0);
  EXPECT_EQ(r90.at(1, 0, 1), 0);
  // The top-right pixel (2, 0) goes to the bottom-right.
  EXPECT_EQ(r90.at(1, 2, 0), 2);
  EXPECT_EQ(r90.at(1, 2, 1), 0);
  EXPECT_EQ(r90.at(1, 2, 2), 7);

  const Image r180 = RotateClockwise(src, 180);
  ASSERT_EQ(r180.width, 3);
  EXPECT_EQ(r180.at(0, 0, 0), 2);
  EXPECT_EQ(r180.at(0, 0, 1), 1);

  // Four quarter turns, and 90 + 270, give the original back.
  Image turned = src;
  for (int k = 0; k < 4; ++k) turned = RotateClockwise(turned, 90);
  EXPECT_EQ(turned.pixels, src.pixels);
  const Image back = RotateClockwise(RotateClockwise(src, 90), 270);
  EXPECT_EQ(back.width, src.width);
  EXPECT_EQ(back.pixels, src.pixels);
  EXPECT_EQ(RotateClockwise(src, 0).pixels, src.pixels);
}

// Larger than the 64-pixel tiles the turn works in, with partial tiles at both edges:
// every pixel lands where the definition puts it.
TEST(RotateClockwise, LargeImagesAcrossTiles) {
  Image src = MakeImage(150, 97, PixelFormat::kRgb8);
  for (size_t i = 0; i < src.pixels.size(); ++i)
    src.pixels[i] = static_cast<uint8_t>(i * 7 + i / 251);
  const Image r90 = RotateClockwise(src, 90), r180 = RotateClockwise(src, 180),
              r270 = RotateClockwise(src, 270);
  ASSERT_EQ(r90.width, 97);
  ASSERT_EQ(r90.height, 150);
  ASSERT_EQ(r270.width, 97);
  for (int y = 0; y < src.height; ++y) {
    for (int x = 0; x < src.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        ASSERT_EQ(r90.at(src.height - 1 - y, x, c), src.at(x, y, c));
        ASSERT_EQ(r180.at(src.width - 1 - x, src.height - 1 - y, c), src.at(x, y, c));
        ASSERT_EQ(r270.at(y, src.width - 1 - x, c), src.at(x, y, c));
      }
    }
  }
}

TEST(RotateClockwise, GrayAndBadAngles) {
  Image gray = MakeImage(2, 1, PixelFormat::kGray8);
  gray.pixels = {10, 20};
  const Image r = RotateClockwise(gray, 270);
  ASSERT_EQ(r.width, 1);
  ASSERT_EQ(r.height, 2);
  EXPECT_EQ(r.at(0, 0), 20);
  EXPECT_EQ(r.at(0, 1), 10);
  EXPECT_THROW(RotateClockwise(gray, 45), std::invalid_argument);
  EXPECT_THROW(RotateClockwise(gray, -90), std::invalid_argument);
}

}  // namespace
}  // namespace arco::media
