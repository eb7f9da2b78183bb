#include "arco/view/view.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>

#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"
#include "arco/view/server.h"
#include "arco/view/video_cache.h"

namespace arco::view {
namespace {

TEST(Base64, Rfc4648Vectors) {
  // RFC 4648 section 10.
  EXPECT_EQ(Base64(""), "");
  EXPECT_EQ(Base64("f"), "Zg==");
  EXPECT_EQ(Base64("fo"), "Zm8=");
  EXPECT_EQ(Base64("foo"), "Zm9v");
  EXPECT_EQ(Base64("foob"), "Zm9vYg==");
  EXPECT_EQ(Base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(Base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(Base64(std::string("\xff\x00\x80", 3)), "/wCA");
}

TEST(WriteViewFolder, RejectsAFolderWithoutResultJson) {
  const arco::testing::TempDir temp;
  const std::string& dir = temp.path();
  std::filesystem::create_directories(dir + "/out");
  ViewOptions options;
  options.result_dir = dir;
  const auto summary = WriteViewFolder(options, dir + "/out");
  ASSERT_FALSE(summary.ok());
  EXPECT_NE(summary.status().message().find("result.json: not found"), std::string::npos)
      << summary.status().message();
  EXPECT_TRUE(std::filesystem::is_empty(dir + "/out"));
}

TEST(ViewOptions, RejectsAnEmptyResultDir) { EXPECT_FALSE(ViewOptions{}.Validate().ok()); }

TEST(ViewOptions, ChecksTheVideoOptions) {
  ViewOptions o;
  o.result_dir = "/tmp";
  EXPECT_TRUE(o.Validate().ok());
  o.video_scale = 0;
  EXPECT_FALSE(o.Validate().ok());
  o.video_scale = 1.5;
  EXPECT_FALSE(o.Validate().ok());
  o.video_scale = 1;
  o.video_cameras = {"cam0"};
  EXPECT_TRUE(o.Validate().ok());
  o.videos = false;  // cameras named, videos off: a contradiction
  EXPECT_FALSE(o.Validate().ok());
  o.videos = true;
  o.video_cameras = {""};
  EXPECT_FALSE(o.Validate().ok());
}

TEST(MissingStages, ListsEveryStageOfAnEmptyFolder) {
  const auto missing = MissingStages("/nonexistent_arco_result");
  ASSERT_EQ(missing.size(), 7u);
  EXPECT_EQ(missing.front().stage, "triangulation");
  EXPECT_EQ(missing.back().stage, "arco");
}

TEST(ServeOptions, RejectsOutOfRangeValues) {
  ServeOptions o;
  o.dir = "/tmp";
  EXPECT_TRUE(o.Validate().ok());
  o.port = 70000;
  EXPECT_FALSE(o.Validate().ok());
  o.port = 0;
  o.exit_after_s = -1;
  EXPECT_FALSE(o.Validate().ok());
  o.exit_after_s = 0;
  o.dir = "";
  EXPECT_FALSE(o.Validate().ok());
}

std::string Digest(const std::string& text) {
  Sha256 h;
  h.Add(text);
  return h.HexDigest();
}

TEST(Sha256, Fips180Vectors) {
  // FIPS 180-4 examples (NIST CSRC, SHA256.pdf) and the empty message.
  EXPECT_EQ(Digest(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(Digest("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(Digest("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
}

TEST(Sha256, FieldsAreUnambiguous) {
  Sha256 a, b;
  a.AddField("x", "1;y=1:2");
  b.AddField("x", "1");
  b.AddField("y", "2");
  EXPECT_NE(a.HexDigest(), b.HexDigest());
}

std::string VideoDigest(const std::string& path, int64_t sample) {
  Sha256 h;
  EXPECT_TRUE(HashVideoSource(h, "v", path, sample).ok());
  return h.HexDigest();
}

TEST(HashVideoSource, SeesTheSizeAndBothEnds) {
  const arco::testing::TempDir temp;
  const std::string& dir = temp.path();
  const std::string path = dir + "/v.bin";
  std::string bytes(100, 'a');
  ASSERT_TRUE(AtomicWriteFile(path, bytes).ok());
  const std::string base = VideoDigest(path, 10);
  bytes[50] = 'b';  // the middle, outside the sampled ends: not seen (documented)
  ASSERT_TRUE(AtomicWriteFile(path, bytes).ok());
  EXPECT_EQ(VideoDigest(path, 10), base);
  bytes[95] = 'b';  // the last 10 bytes
  ASSERT_TRUE(AtomicWriteFile(path, bytes).ok());
  const std::string tail = VideoDigest(path, 10);
  EXPECT_NE(tail, base);
  bytes[2] = 'b';  // the first 10 bytes
  ASSERT_TRUE(AtomicWriteFile(path, bytes).ok());
  EXPECT_NE(VideoDigest(path, 10), tail);
  // The size alone: same ends, one byte longer.
  ASSERT_TRUE(AtomicWriteFile(path, std::string(100, 'a')).ok());
  const std::string hundred = VideoDigest(path, 10);
  ASSERT_TRUE(AtomicWriteFile(path, std::string(101, 'a')).ok());
  EXPECT_NE(VideoDigest(path, 10), hundred);
  Sha256 missing;
  EXPECT_FALSE(HashVideoSource(missing, "v", dir + "/none.mp4").ok());
}

TEST(EvictVideoCache, RemovesTheLeastRecentlyUsedBeyondTheBound) {
  namespace fs = std::filesystem;
  const arco::testing::TempDir temp;
  const std::string& dir = temp.path();
  const auto now = fs::file_time_type::clock::now();
  // Entries a (oldest) .. d (newest), 100 bytes of video + 10 of sidecar each.
  const char* keys[] = {"a", "b", "c", "d"};
  for (int i = 0; i < 4; ++i) {
    const VideoCacheEntry e = CacheEntryPaths(dir, keys[i]);
    ASSERT_TRUE(AtomicWriteFile(e.video, std::string(100, 'v')).ok());
    ASSERT_TRUE(AtomicWriteFile(e.sidecar, std::string(10, 's')).ok());
    fs::last_write_time(e.video, now - std::chrono::minutes(10 - i));
  }
  // A temporary of an interrupted encode, two days old, and a fresh one (in progress).
  ASSERT_TRUE(AtomicWriteFile(dir + "/.old-1.webm", "x").ok());
  fs::last_write_time(dir + "/.old-1.webm", now - std::chrono::hours(48));
  ASSERT_TRUE(AtomicWriteFile(dir + "/.new-2.webm", "x").ok());

  // Within the bound: nothing removed but the stale temporary.
  auto removed = EvictVideoCache(dir, 440, {});
  ASSERT_TRUE(removed.ok());
  EXPECT_EQ(*removed, 0);
  EXPECT_FALSE(fs::exists(dir + "/.old-1.webm"));
  EXPECT_TRUE(fs::exists(dir + "/.new-2.webm"));
  // 220 bytes: two entries go, the oldest (a) kept because it is in use, so b and c.
  removed = EvictVideoCache(dir, 220, {"a"});
  ASSERT_TRUE(removed.ok());
  EXPECT_EQ(*removed, 2);
  EXPECT_TRUE(fs::exists(CacheEntryPaths(dir, "a").video));
  EXPECT_FALSE(fs::exists(CacheEntryPaths(dir, "b").video));
  EXPECT_FALSE(fs::exists(CacheEntryPaths(dir, "b").sidecar));
  EXPECT_FALSE(fs::exists(CacheEntryPaths(dir, "c").video));
  EXPECT_TRUE(fs::exists(CacheEntryPaths(dir, "d").video));
  EXPECT_TRUE(fs::exists(CacheEntryPaths(dir, "d").sidecar));
  fs::remove_all(dir);
}

TEST(DefaultVideoCacheDir, FollowsXdgThenHome) {
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  const char* home = std::getenv("HOME");
  const std::string old_xdg = xdg ? xdg : "", old_home = home ? home : "";
  setenv("XDG_CACHE_HOME", "/x/cache", 1);
  setenv("HOME", "/h", 1);
  EXPECT_EQ(DefaultVideoCacheDir(), "/x/cache/arco/view");
  setenv("XDG_CACHE_HOME", "relative", 1);  // invalid by the specification: ignored
  EXPECT_EQ(DefaultVideoCacheDir(), "/h/.cache/arco/view");
  unsetenv("XDG_CACHE_HOME");
  EXPECT_EQ(DefaultVideoCacheDir(), "/h/.cache/arco/view");
  unsetenv("HOME");
  EXPECT_EQ(DefaultVideoCacheDir(), "");
  if (xdg) setenv("XDG_CACHE_HOME", old_xdg.c_str(), 1);
  if (home) setenv("HOME", old_home.c_str(), 1);
}

}  // namespace
}  // namespace arco::view
