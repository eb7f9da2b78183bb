#include "arco/media/video_reader.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "arco/media/test_video.h"
#include "arco/testing/temp_dir.h"

namespace arco::media {
namespace {

namespace fs = std::filesystem;
using testing::IndexVideo;

class VideoReaderTest : public ::testing::Test {
 protected:
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  arco::testing::TempDir temp_;
  const fs::path dir_{temp_.path()};
};

// Seeks to random frames (and back) and checks each frame shows its index.
void ExpectFrameAccurateSeeks(VideoReader* reader, int frames, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> pick(0, frames - 1);
  Image frame;
  for (int trial = 0; trial < 40; ++trial) {
    const int n = trial == 0 ? frames - 1 : trial == 1 ? 0 : pick(rng);
    const Status seek = reader->Seek(n);
    ASSERT_TRUE(seek.ok()) << seek.message();
    ASSERT_EQ(reader->next_frame(), n);
    auto got = reader->Read(&frame);
    ASSERT_TRUE(got.ok()) << got.status().message();
    ASSERT_TRUE(*got) << "frame " << n;
    EXPECT_EQ(testing::ReadIndex(frame), n) << "seek to " << n << " (trial " << trial << ")";
    EXPECT_EQ(reader->next_frame(), n + 1);
  }
}

void ExpectSequentialFrames(VideoReader* reader, int frames) {
  ASSERT_TRUE(reader->Seek(0).ok());
  Image frame;
  for (int k = 0; k < frames; ++k) {
    auto got = reader->Read(&frame);
    ASSERT_TRUE(got.ok() && *got) << "frame " << k;
    ASSERT_EQ(testing::ReadIndex(frame), k);
  }
  auto end = reader->Read(&frame);
  ASSERT_TRUE(end.ok());
  EXPECT_FALSE(*end) << "a frame after the last one";
}

struct Case {
  const char* name;
  IndexVideo video;
  FrameCountSource count_source;
};

TEST_F(VideoReaderTest, SeeksToEveryFrameAndReportsProperties) {
  std::vector<Case> cases;
  {
    IndexVideo v;  // lossless, intra only, Matroska (no frame count in the container)
    cases.push_back({"ffv1.mkv", v, FrameCountSource::kCountedPackets});
  }
  {
    IndexVideo v;  // lossy, key frame every 10, B-frames (reordered), NTSC rate
    v.container = "mp4";
    v.codec = "mpeg4";
    v.fps = Rational{30000, 1001};
    v.frames = 95;
    v.gop = 10;
    v.b_frames = 2;
    v.rotation_deg = 90;
    cases.push_back({"mpeg4.mp4", v, FrameCountSource::kContainer});
  }
  {
    IndexVideo v;
    v.container = "avi";
    v.codec = "mpeg4";
    v.fps = Rational{25, 1};
    v.frames = 70;
    v.gop = 25;
    cases.push_back({"mpeg4.avi", v, FrameCountSource::kContainer});
  }
  if (testing::HasEncoder("libx264")) {
    IndexVideo v;  // H.264 with B-frames in Matroska: timestamps from the container
    v.codec = "libx264";
    v.fps = Rational{60, 1};
    v.frames = 130;
    v.gop = 30;
    v.b_frames = 3;
    cases.push_back({"h264.mkv", v, FrameCountSource::kCountedPackets});
    v.container = "mp4";
    v.rotation_deg = 270;
    cases.push_back({"h264.mp4", v, FrameCountSource::kContainer});
  }
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = Path(c.name);
    const Status written = testing::WriteIndexVideo(path, c.video);
    ASSERT_TRUE(written.ok()) << written.message();
    for (PixelFormat format : {PixelFormat::kGray8, PixelFormat::kRgb8}) {
      VideoReaderOptions options;
      options.format = format;
      auto reader = VideoReader::Open(path, options);
      ASSERT_TRUE(reader.ok()) << reader.status().message();
      const VideoProperties& p = reader->properties();
      EXPECT_EQ(p.path, path);
      EXPECT_EQ(p.fps.num, c.video.fps.num);
      EXPECT_EQ(p.fps.den, c.video.fps.den);
      EXPECT_DOUBLE_EQ(p.fps_hz, double(c.video.fps.num) / c.video.fps.den);
      EXPECT_EQ(p.frame_count, c.video.frames);
      EXPECT_EQ(p.frame_count_source, c.count_source);
      EXPECT_EQ(p.width, c.video.width);
      EXPECT_EQ(p.height, c.video.height);
      EXPECT_EQ(p.rotation_deg, c.video.rotation_deg);
      EXPECT_NEAR(p.duration_s, c.video.frames * double(c.video.fps.den) / c.video.fps.num, 1e-9);
      ExpectSequentialFrames(&*reader, c.video.frames);
      ExpectFrameAccurateSeeks(&*reader, c.video.frames, 7);
    }
  }
}

TEST_F(VideoReaderTest, ScalesDownKeepingTheAspectRatio) {
  IndexVideo v;
  ASSERT_TRUE(testing::WriteIndexVideo(Path("v.mkv"), v).ok());
  VideoReaderOptions options;
  options.format = PixelFormat::kGray8;
  options.max_width = 64;
  auto reader = VideoReader::Open(Path("v.mkv"), options);
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  EXPECT_EQ(reader->properties().width, 64);
  EXPECT_EQ(reader->properties().height, 48);
  EXPECT_EQ(reader->properties().coded_width, 128);
  auto frame = reader->ReadFrame(37);
  ASSERT_TRUE(frame.ok()) << frame.status().message();
  EXPECT_EQ(frame->width, 64);
  EXPECT_EQ(frame->height, 48);
  EXPECT_EQ(frame->pixels.size(), 64u * 48u);
  EXPECT_EQ(testing::ReadIndex(*frame), 37);
}

TEST_F(VideoReaderTest, RgbFramesArePackedRowMajor) {
  IndexVideo v;
  ASSERT_TRUE(testing::WriteIndexVideo(Path("v.mkv"), v).ok());
  auto reader = VideoReader::Open(Path("v.mkv"));
  ASSERT_TRUE(reader.ok());
  auto frame = reader->ReadFrame(5);  // bits 0 and 2: blocks (0, 0) and (2, 0) bright
  ASSERT_TRUE(frame.ok());
  EXPECT_EQ(frame->format, PixelFormat::kRgb8);
  EXPECT_EQ(frame->pixels.size(), 128u * 96u * 3u);
  // Neutral chroma: R = G = B = the written gray levels 215 / 40 (through yuv420p).
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(frame->at(16, 16, c), 215, 3);
    EXPECT_NEAR(frame->at(48, 16, c), 40, 3);
    EXPECT_NEAR(frame->at(80, 16, c), 215, 3);
    EXPECT_EQ(frame->at(16, 16, c), frame->row(16)[16 * 3 + c]);
  }
}

TEST_F(VideoReaderTest, ReadsImageFoldersInNaturalOrder) {
  // frame_0.png ... frame_11.png: frame_10 sorts after frame_9; other files are ignored.
  IndexVideo v;
  const int frames = 12;
  const fs::path folder = dir_ / "images";
  fs::create_directories(folder);
  for (int k = 0; k < frames; ++k) {
    const std::string file = (folder / ("frame_" + std::to_string(k) + ".png")).string();
    const Status written = testing::WriteIndexPng(file, v, k);
    ASSERT_TRUE(written.ok()) << written.message();
  }
  std::FILE* notes = std::fopen((folder / "notes.txt").c_str(), "wb");
  std::fclose(notes);
  VideoReaderOptions options;
  options.image_fps = Rational{24, 1};
  auto reader = VideoReader::Open(folder.string(), options);
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  const VideoProperties& p = reader->properties();
  EXPECT_EQ(p.frame_count, frames);
  EXPECT_EQ(p.frame_count_source, FrameCountSource::kImageFiles);
  EXPECT_EQ(p.fps.num, 24);
  EXPECT_DOUBLE_EQ(p.duration_s, 0.5);
  EXPECT_EQ(p.codec, "png");
  EXPECT_EQ(p.width, 128);
  EXPECT_EQ(p.height, 96);
  ExpectSequentialFrames(&*reader, frames);
  ExpectFrameAccurateSeeks(&*reader, frames, 3);

  // One image: one frame, no frame rate unless given.
  auto single = VideoReader::Open((folder / "frame_7.png").string());
  ASSERT_TRUE(single.ok()) << single.status().message();
  EXPECT_EQ(single->properties().frame_count, 1);
  EXPECT_EQ(single->properties().fps_hz, 0.0);
  auto frame = single->ReadFrame(0);
  ASSERT_TRUE(frame.ok()) << frame.status().message();
  EXPECT_EQ(testing::ReadIndex(*frame), 7);

  // A differently sized image is an error naming it.
  IndexVideo small = v;
  small.width = 64;
  ASSERT_TRUE(testing::WriteIndexPng((folder / "frame_12.png").string(), small, 12).ok());
  auto mixed = VideoReader::Open(folder.string());
  ASSERT_TRUE(mixed.ok());
  auto bad = mixed->ReadFrame(12);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().message().rfind((folder / "frame_12.png").string(), 0), 0u)
      << bad.status().message();
}

TEST_F(VideoReaderTest, ErrorsNameTheFile) {
  auto missing = VideoReader::Open(Path("missing.mp4"));
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().message().rfind(Path("missing.mp4"), 0), 0u)
      << missing.status().message();
  {
    std::FILE* f = std::fopen(Path("junk.mp4").c_str(), "wb");
    std::fputs("not a video at all", f);
    std::fclose(f);
  }
  auto junk = VideoReader::Open(Path("junk.mp4"));
  ASSERT_FALSE(junk.ok());
  EXPECT_EQ(junk.status().message().rfind(Path("junk.mp4"), 0), 0u) << junk.status().message();
  fs::create_directories(dir_ / "empty");
  auto empty = VideoReader::Open((dir_ / "empty").string());
  ASSERT_FALSE(empty.ok());
  EXPECT_NE(empty.status().message().find("no image files"), std::string::npos);

  IndexVideo v;
  ASSERT_TRUE(testing::WriteIndexVideo(Path("v.mkv"), v).ok());
  auto reader = VideoReader::Open(Path("v.mkv"));
  ASSERT_TRUE(reader.ok());
  const Status past = reader->Seek(v.frames);
  ASSERT_FALSE(past.ok());
  EXPECT_EQ(past.message(), Path("v.mkv") + ": frame 60 is outside [0, 60)");
  EXPECT_FALSE(reader->Seek(-1).ok());

  VideoReaderOptions bad;
  bad.max_width = -1;
  auto invalid = VideoReader::Open(Path("v.mkv"), bad);
  ASSERT_FALSE(invalid.ok());
  EXPECT_EQ(invalid.status().message(), Path("v.mkv") + ": max_width must be >= 0");
}

}  // namespace
}  // namespace arco::media
