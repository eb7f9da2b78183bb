// Real videos from Debian's opencv-doc package (installed by scripts/setup): every
// frame reached by Seek must be the frame sequential reading gives at that index.
#include <filesystem>
#include <functional>
#include <random>
#include <string_view>

#include <gtest/gtest.h>

#include "arco/media/video_reader.h"

namespace arco::media {
namespace {

const char* kOpenCvData = "/usr/share/doc/opencv-doc/examples/data";

size_t Hash(const Image& image) {
  return std::hash<std::string_view>{}(std::string_view(
      reinterpret_cast<const char*>(image.pixels.data()), image.pixels.size()));
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
  std::printf("%s: %s %dx%d, %d/%d fps, %lld frames\n", name.c_str(), p.codec.c_str(), p.width,
              p.height, p.fps.num, p.fps.den, static_cast<long long>(p.frame_count));
}

TEST(RealVideo, VtestSeeksMatchSequentialReading) { CheckSeeksMatchSequentialReading("vtest.avi"); }
TEST(RealVideo, TreeSeeksMatchSequentialReading) { CheckSeeksMatchSequentialReading("tree.avi"); }
TEST(RealVideo, MegamindSeeksMatchSequentialReading) {
  CheckSeeksMatchSequentialReading("Megamind.avi");
}

}  // namespace
}  // namespace arco::media
