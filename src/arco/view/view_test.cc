#include "arco/view/view.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "arco/util/file_io.h"
#include "arco/view/server.h"

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
  const std::string dir =
      (std::filesystem::temp_directory_path() / "arco_view_test_empty").string();
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir + "/out");
  ViewOptions options;
  options.result_dir = dir;
  const auto summary = WriteViewFolder(options, dir + "/out");
  ASSERT_FALSE(summary.ok());
  EXPECT_NE(summary.status().message().find("result.json: not found"), std::string::npos)
      << summary.status().message();
  EXPECT_TRUE(std::filesystem::is_empty(dir + "/out"));
  std::filesystem::remove_all(dir);
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

}  // namespace
}  // namespace arco::view
