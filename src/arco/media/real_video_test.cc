// Real videos from Debian's opencv-doc package (installed by scripts/setup): every
// frame reached by Seek must be the frame sequential reading gives at that index.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <random>
#include <string_view>

#include "arco/media/video_reader.h"

namespace arco::media {
namespace {

const char* kOpenCvData = "/usr/share/doc/opencv-doc/examples/data";

size_t Hash(const Image& image) {
  return std::hash<std::string_view>{}(
      std::string_view(reinterpret_cast<const char*>(image.pixels.data()), image.pixels.size()));
}

void CheckSeeksMatchSequentialReading(const std::string& name) {
  const std::string path = std::string(kOpenCvData) + "/" + name;
  if (!std::filesystem::exists(path)) {
    GTEST_SKIP() << path << " missing (Debian package opencv-doc; scripts/setup installs it)";
  }
  VideoReaderOptions options;
  options.format = PixelFormat::kGray8;
  auto reader = VideoReader::Open(path, options);
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  const VideoProperties p = reader->properties();
  EXPECT_GT(p.fps_hz, 0);
  EXPECT_GT(p.width, 0);
  EXPECT_GT(p.height, 0);
  EXPECT_EQ(p.rotation_deg, 0);
  std::vector<size_t> hashes;
  Image frame;
  while (true) {
    auto got = reader->Read(&frame);
    ASSERT_TRUE(got.ok()) << got.status().message();
    if (!*got) break;
    ASSERT_EQ(frame.width, p.width);
    hashes.push_back(Hash(frame));
  }
  EXPECT_EQ(static_cast<int64_t>(hashes.size()), p.frame_count) << path;
  std::mt19937 rng(11);
  std::uniform_int_distribution<int64_t> pick(0, static_cast<int64_t>(hashes.size()) - 1);
  for (int trial = 0; trial < 25; ++trial) {
    const int64_t n = trial == 0 ? static_cast<int64_t>(hashes.size()) - 1 : pick(rng);
    auto seek = reader->ReadFrame(n);
    ASSERT_TRUE(seek.ok()) << seek.status().message();
    EXPECT_EQ(Hash(*seek), hashes[static_cast<size_t>(n)]) << path << " frame " << n;
  }
  std::printf("%s: %s %dx%d, %d/%d fps, %lld frames\n",
              name.c_str(),
              p.codec.c_str(),
              p.width,
              p.height,
              p.fps.num,
              p.fps.den,
              static_cast<long long>(p.frame_count));
}

TEST(RealVideo, VtestSeeksMatchSequentialReading) { CheckSeeksMatchSequentialReading("vtest.avi"); }
TEST(RealVideo, TreeSeeksMatchSequentialReading) { CheckSeeksMatchSequentialReading("tree.avi"); }
TEST(RealVideo, MegamindSeeksMatchSequentialReading) {
  CheckSeeksMatchSequentialReading("Megamind.avi");
}

}  // namespace
}  // namespace arco::media

namespace arco::media {
namespace {

// SPD's example frame, a 2300x2656 JPEG: swscale's SIMD conversion wrote past the end of
// a tightly packed RGB buffer of this width (caught by valgrind / the address sanitizer),
// so the reader converts into padded rows. The frame's last pixels must be the image's.
TEST(RealImage, LargeJpegConvertsWithoutOverrun) {
  const std::string path = std::string(ARCO_SHARED_DATA_DIR) + "/spd/example.jpg";
  for (PixelFormat format : {PixelFormat::kRgb8, PixelFormat::kGray8}) {
    VideoReaderOptions options;
    options.format = format;
    auto reader = VideoReader::Open(path, options);
    ASSERT_TRUE(reader.ok()) << reader.status().message();
    EXPECT_EQ(reader->properties().width, 2300);
    EXPECT_EQ(reader->properties().height, 2656);
    EXPECT_EQ(reader->properties().frame_count, 1);
    auto frame = reader->ReadFrame(0);
    ASSERT_TRUE(frame.ok()) << frame.status().message();
    ASSERT_EQ(frame->pixels.size(), 2300u * 2656u * frame->channels());
    // Not all one value: the rows were copied out (the photo has texture everywhere).
    int64_t sum = 0, sum2 = 0;
    for (int x = 0; x < 2300; ++x) {
      const int v = frame->at(x, 2655, 0);
      sum += v;
      sum2 += v * v;
    }
    EXPECT_GT(sum2 * 2300 - sum * sum, 0) << "the last row is constant";
  }
}

}  // namespace
}  // namespace arco::media
