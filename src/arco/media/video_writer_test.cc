#include "arco/media/video_writer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "arco/media/video_reader.h"
#include "arco/testing/temp_dir.h"

namespace arco::media {
namespace {

namespace fs = std::filesystem;

class VideoWriterTest : public ::testing::Test {
 protected:
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  arco::testing::TempDir temp_;
  const fs::path dir_{temp_.path()};
};

// Frame k: noise (every value 0..255 occurs) over smooth gradients that move with k.
Image TestFrame(int width, int height, PixelFormat format, int k, bool noisy) {
  Image image = MakeImage(width, height, format);
  uint32_t state = 12345u + 977u * k;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < image.channels(); ++c) {
        state = state * 1664525u + 1013904223u;
        const double smooth = 127.5 + 100 * std::sin(0.05 * (x + 3 * k) + 0.7 * c) *
                                          std::cos(0.04 * (y - 2 * k) + 0.3 * c);
        const int value = noisy ? static_cast<int>(state >> 24) : static_cast<int>(smooth);
        image.row(y)[x * image.channels() + c] = static_cast<uint8_t>(value);
      }
    }
  }
  return image;
}

double Psnr(const Image& a, const Image& b) {
  double sum = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    const double d = double(a.pixels[i]) - double(b.pixels[i]);
    sum += d * d;
  }
  const double mse = sum / a.pixels.size();
  return mse == 0 ? 99 : 10 * std::log10(255.0 * 255.0 / mse);
}

struct RoundTrip {
  VideoProperties properties;
  std::vector<Image> frames;
};

RoundTrip ReadAll(const std::string& path, PixelFormat format) {
  VideoReaderOptions options;
  options.format = format;
  auto reader = VideoReader::Open(path, options);
  EXPECT_TRUE(reader.ok()) << reader.status().message();
  RoundTrip result;
  if (!reader.ok()) return result;
  result.properties = reader->properties();
  Image frame;
  while (true) {
    auto more = reader->Read(&frame);
    EXPECT_TRUE(more.ok()) << more.status().message();
    if (!more.ok() || !*more) break;
    result.frames.push_back(frame);
  }
  return result;
}

TEST_F(VideoWriterTest, Ffv1RoundTripIsBitExactWithPropertiesReadBack) {
  for (PixelFormat format : {PixelFormat::kRgb8, PixelFormat::kGray8}) {
    SCOPED_TRACE(PixelFormatName(format));
    const std::string path = Path(std::string("lossless_") + PixelFormatName(format) + ".mkv");
    VideoWriterOptions options;  // FFV1 in Matroska
    options.width = 67;          // odd sides: planar RGB and gray have no chroma subsampling
    options.height = 45;
    options.fps = {30000, 1001};
    options.source_format = format;
    std::vector<Image> written;
    {
      auto writer = VideoWriter::Open(path, options);
      ASSERT_TRUE(writer.ok()) << writer.status().message();
      for (int k = 0; k < 9; ++k) {
        written.push_back(TestFrame(options.width, options.height, format, k, /*noisy=*/true));
        const Status status = writer->Write(written.back());
        ASSERT_TRUE(status.ok()) << status.message();
      }
      EXPECT_EQ(writer->frames_written(), 9);
      const Status closed = writer->Close();
      ASSERT_TRUE(closed.ok()) << closed.message();
    }
    const RoundTrip back = ReadAll(path, format);
    EXPECT_EQ(back.properties.codec, "ffv1");
    EXPECT_EQ(back.properties.fps.num, 30000);
    EXPECT_EQ(back.properties.fps.den, 1001);
    EXPECT_EQ(back.properties.frame_count, 9);
    EXPECT_EQ(back.properties.width, 67);
    EXPECT_EQ(back.properties.height, 45);
    ASSERT_EQ(back.frames.size(), written.size());
    for (size_t k = 0; k < written.size(); ++k) {
      EXPECT_TRUE(back.frames[k].pixels == written[k].pixels) << "frame " << k << " differs";
    }
  }
}

TEST_F(VideoWriterTest, SameFramesGiveTheSameBytes) {
  for (const char* container : {"matroska", "mp4"}) {
    SCOPED_TRACE(container);
    std::string bytes[2];
    for (int run = 0; run < 2; ++run) {
      const std::string path = Path("same" + std::to_string(run) + "." + container);
      VideoWriterOptions options;
      options.container = container;
      options.codec = std::string(container) == "mp4" ? "mpeg4" : "ffv1";
      options.width = 64;
      options.height = 48;
      auto writer = VideoWriter::Open(path, options);
      ASSERT_TRUE(writer.ok()) << writer.status().message();
      for (int k = 0; k < 4; ++k) {
        ASSERT_TRUE(writer->Write(TestFrame(64, 48, PixelFormat::kRgb8, k, true)).ok());
      }
      ASSERT_TRUE(writer->Close().ok());
      std::ifstream in(path, std::ios::binary);
      bytes[run].assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    EXPECT_GT(bytes[0].size(), 1000u);
    EXPECT_TRUE(bytes[0] == bytes[1]) << "the two files differ";
  }
}

TEST_F(VideoWriterTest, RotationIsReadBackInEveryContainer) {
  struct Case {
    const char* file;
    const char* container;
    const char* codec;
    int rotation_deg;
  };
  for (const Case& c : {Case{"r90.mp4", "mp4", "mpeg4", 90},
                        Case{"r270.mp4", "mp4", "mpeg4", 270},
                        Case{"r180.mov", "mov", "ffv1", 180}}) {
    SCOPED_TRACE(c.file);
    VideoWriterOptions options;
    options.container = c.container;
    options.codec = c.codec;
    options.width = 64;
    options.height = 48;
    options.rotation_deg = c.rotation_deg;
    auto writer = VideoWriter::Open(Path(c.file), options);
    ASSERT_TRUE(writer.ok()) << writer.status().message();
    for (int k = 0; k < 5; ++k) {
      ASSERT_TRUE(writer->Write(TestFrame(64, 48, PixelFormat::kRgb8, k, false)).ok());
    }
    ASSERT_TRUE(writer->Close().ok());
    auto reader = VideoReader::Open(Path(c.file));
    ASSERT_TRUE(reader.ok()) << reader.status().message();
    EXPECT_EQ(reader->properties().rotation_deg, c.rotation_deg);
    EXPECT_EQ(reader->properties().frame_count, 5);
    EXPECT_EQ(reader->properties().width, 64);  // stored as given, not turned
  }
}

TEST_F(VideoWriterTest, LossyCodecsRoundTripWithinPsnr) {
  std::vector<std::pair<std::string, std::string>> cases = {{"mp4", "mpeg4"}, {"avi", "mpeg4"}};
  if (HasVideoEncoder("libx264")) cases.push_back({"mp4", "libx264"});
  // VP8 in WebM: arco view's videos (exporter::WriteOverlay's .webm).
  if (HasVideoEncoder("libvpx")) cases.push_back({"webm", "libvpx"});
  for (const auto& [container, codec] : cases) {
    SCOPED_TRACE(container + "/" + codec);
    const std::string path = Path(codec + "." + container);
    VideoWriterOptions options;
    options.container = container;
    options.codec = codec;
    options.width = 160;
    options.height = 96;
    options.fps = {25, 1};
    options.b_frames = 2;
    std::vector<Image> written;
    {
      auto writer = VideoWriter::Open(path, options);
      ASSERT_TRUE(writer.ok()) << writer.status().message();
      for (int k = 0; k < 20; ++k) {
        written.push_back(TestFrame(160, 96, PixelFormat::kRgb8, k, /*noisy=*/false));
        ASSERT_TRUE(writer->Write(written.back()).ok());
      }
      ASSERT_TRUE(writer->Close().ok());
    }
    const RoundTrip back = ReadAll(path, PixelFormat::kRgb8);
    EXPECT_EQ(back.properties.frame_count, 20);
    EXPECT_EQ(back.properties.fps.num, 25);
    ASSERT_EQ(back.frames.size(), written.size());
    for (size_t k = 0; k < written.size(); ++k) {
      // yuv420p halves the chroma resolution: smooth frames keep > 30 dB.
      EXPECT_GT(Psnr(back.frames[k], written[k]), 30.0) << "frame " << k;
    }
    // Frames are told apart (the order survives B-frame reordering).
    EXPECT_LT(Psnr(back.frames[3], written[8]), 25.0);
  }
}

TEST_F(VideoWriterTest, PngImageRoundTripIsExact) {
  for (PixelFormat format : {PixelFormat::kRgb8, PixelFormat::kGray8}) {
    const std::string path = Path(std::string("image_") + PixelFormatName(format) + ".png");
    const Image image = TestFrame(33, 21, format, 4, /*noisy=*/true);
    const Status written = WriteImageFile(path, image);
    ASSERT_TRUE(written.ok()) << written.message();
    VideoReaderOptions options;
    options.format = format;
    auto back = VideoReader::Open(path, options);
    ASSERT_TRUE(back.ok()) << back.status().message();
    auto frame = back->ReadFrame(0);
    ASSERT_TRUE(frame.ok()) << frame.status().message();
    EXPECT_TRUE(frame->pixels == image.pixels);
  }
}

TEST_F(VideoWriterTest, ErrorsNameTheFileAndTheReason) {
  VideoWriterOptions options;
  options.width = 64;
  options.height = 48;

  const std::string missing = Path("no/such/folder/v.mkv");
  auto bad_path = VideoWriter::Open(missing, options);
  ASSERT_FALSE(bad_path.ok());
  EXPECT_EQ(bad_path.status().message().rfind(missing + ": cannot create the file: ", 0), 0u)
      << bad_path.status().message();
  EXPECT_NE(bad_path.status().message().find("No such file"), std::string::npos);

  VideoWriterOptions odd = options;
  odd.container = "mp4";
  odd.codec = "mpeg4";
  odd.width = 65;
  auto odd_size = VideoWriter::Open(Path("odd.mp4"), odd);
  ASSERT_FALSE(odd_size.ok());
  EXPECT_EQ(
      odd_size.status().message().rfind(Path("odd.mp4") + ": 65x48 cannot be stored as yuv420p", 0),
      0u)
      << odd_size.status().message();

  VideoWriterOptions unknown = options;
  unknown.codec = "no_such_codec";
  auto no_codec = VideoWriter::Open(Path("x.mkv"), unknown);
  ASSERT_FALSE(no_codec.ok());
  EXPECT_NE(no_codec.status().message().find("no video encoder 'no_such_codec'"),
            std::string::npos);

  VideoWriterOptions bad = options;
  bad.rotation_deg = 45;
  EXPECT_FALSE(bad.Validate().ok());
  EXPECT_FALSE(VideoWriter::Open(Path("r.mkv"), bad).ok());
  bad = options;  // Matroska would drop the rotation
  bad.rotation_deg = 90;
  auto no_rotation = VideoWriter::Open(Path("r90.mkv"), bad);
  ASSERT_FALSE(no_rotation.ok());
  EXPECT_NE(no_rotation.status().message().find("cannot store a display rotation"),
            std::string::npos);
  bad = options;
  bad.width = 0;
  EXPECT_FALSE(VideoWriter::Open(Path("w.mkv"), bad).ok());
  bad = options;
  bad.fps = {0, 1};
  EXPECT_FALSE(bad.Validate().ok());
  bad = options;
  bad.pixel_format = "yuv420p";  // FFV1 stores it, an unknown name is refused
  EXPECT_TRUE(VideoWriter::Open(Path("y.mkv"), bad).ok());
  bad.pixel_format = "not_a_format";
  EXPECT_FALSE(VideoWriter::Open(Path("y2.mkv"), bad).ok());

  auto writer = VideoWriter::Open(Path("size.mkv"), options);
  ASSERT_TRUE(writer.ok()) << writer.status().message();
  const Status wrong = writer->Write(MakeImage(32, 48, PixelFormat::kRgb8));
  ASSERT_FALSE(wrong.ok());
  EXPECT_EQ(wrong.message(), Path("size.mkv") + ": frame 0 is 32x48, the video 64x48");
  EXPECT_FALSE(writer->Write(MakeImage(64, 48, PixelFormat::kRgb8)).ok()) << "failure is sticky";
  EXPECT_FALSE(writer->Close().ok());

  auto closed = VideoWriter::Open(Path("closed.mkv"), options);
  ASSERT_TRUE(closed.ok());
  ASSERT_TRUE(closed->Close().ok());
  EXPECT_TRUE(closed->Close().ok());
  EXPECT_FALSE(closed->Write(MakeImage(64, 48, PixelFormat::kRgb8)).ok());
}

}  // namespace
}  // namespace arco::media
