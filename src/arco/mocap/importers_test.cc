#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "arco/mocap/labelme.h"
#include "arco/mocap/spd_import.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"

namespace arco {
namespace {

using testing::TempDir;

const std::string kLabels = std::string(ARCO_SHARED_DATA_DIR) + "/spd/labels_frame128/";

TEST(Labelme, ReadsRealSpdLabelsAndIgnoresTheRectangle) {
  auto a = ReadLabelme(kLabels + "cello_1113_scale_21334181_128.json");
  ASSERT_TRUE(a.ok()) << a.status().message();
  EXPECT_EQ(a->points.size(), 9u);  // 9 points; the "cello" rectangle is not a point
  EXPECT_EQ(a->Find("cello"), -1);
  EXPECT_EQ(a->image_width, 2300);
  EXPECT_EQ(a->image_height, 2656);
  const int scroll = a->Find("scroll_top");
  ASSERT_GE(scroll, 0);
  // The file says [1350.0, 617.0212765957447] in labelme's corner-origin coordinates.
  EXPECT_DOUBLE_EQ(a->points[scroll].pixel.x(), 1349.5);
  EXPECT_DOUBLE_EQ(a->points[scroll].pixel.y(), 617.0212765957447 - 0.5);
  auto centre = ReadLabelme(kLabels + "cello_1113_scale_21334181_128.json", PixelOrigin::kCenter);
  ASSERT_TRUE(centre.ok());
  EXPECT_DOUBLE_EQ(centre->points[scroll].pixel.x(), 1350.0);
  auto example = ReadLabelme(std::string(ARCO_SHARED_DATA_DIR) + "/spd/example.json");
  ASSERT_TRUE(example.ok()) << example.status().message();
  EXPECT_GE(example->Find("neck_bottom_l"), 0);
}

TEST(Labelme, MalformedFilesAreErrors) {
  auto err = [](const std::string& text) {
    auto r = ParseLabelme(text, "v.json");
    EXPECT_FALSE(r.ok()) << text;
    if (!r.ok()) {
      EXPECT_EQ(r.status().message().rfind("v.json", 0), 0u) << r.status().message();
    }
    return r.ok() ? std::string() : r.status().message();
  };
  auto point = [](const std::string& label, const std::string& xy) {
    return "{\"label\": \"" + label + "\", \"shape_type\": \"point\", \"points\": [" + xy + "]}";
  };
  EXPECT_NE(err("{\"shapes\": [").find("malformed JSON"), std::string::npos);
  EXPECT_NE(err("{\"version\": \"5\"}").find("shapes"), std::string::npos);
  EXPECT_NE(err("[]").find("object"), std::string::npos);
  EXPECT_NE(err("{\"shapes\": [" + point("a", "[NaN, 3]") + "]}").find("NaN"), std::string::npos);
  EXPECT_NE(err("{\"shapes\": [" + point("a", "[1, 2]") + ", " + point("a", "[3, 4]") + "]}")
                .find("more than one"),
            std::string::npos);
  err("{\"shapes\": [" + point("a", "[1, 2], [3, 4]") + "]}");
  err("{\"shapes\": [" + point("a", "[1]") + "]}");
  err("{\"shapes\": [" + point("a", "[\"1\", 2]") + "]}");
  err("{\"shapes\": [" + point("", "[1, 2]") + "]}");
  err("{\"shapes\": [7]}");
  err("{\"imageWidth\": -5, \"shapes\": []}");
  auto ok = ParseLabelme("{\"shapes\": [" + point("a", "[1, 2]") +
                             ", {\"label\": \"box\", \"shape_type\": \"rectangle\", "
                             "\"points\": [[0, 0], [5, 5]]}]}",
                         "v.json");
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(ok->points.size(), 1u);
  EXPECT_FALSE(ReadLabelme("/nonexistent.json").ok());
}

TEST(SpdFrame, ParsesRowsWithBareNaN) {
  auto rows = ParseSpdFrame("[[1.5, 2, 0.9], [NaN, NaN, 0.0], [3, -4e2, 1]]", "1.json");
  ASSERT_TRUE(rows.ok()) << rows.status().message();
  ASSERT_EQ(rows->size(), 3u);
  EXPECT_EQ((*rows)[0], Eigen::Vector3d(1.5, 2, 0.9));
  EXPECT_TRUE(std::isnan((*rows)[1].x()));
  EXPECT_EQ((*rows)[1].z(), 0.0);
  EXPECT_EQ((*rows)[2].y(), -400);
  EXPECT_FALSE(ParseSpdFrame("[[1, 2]]", "1.json").ok());
  EXPECT_FALSE(ParseSpdFrame("{\"a\": 1}", "1.json").ok());
  EXPECT_FALSE(ParseSpdFrame("[[1, 2, \"x\"]]", "1.json").ok());
  EXPECT_FALSE(ParseSpdFrame("[[1, 2, 3]", "1.json").ok());
}

TEST(SpdSummary, ReadsFramesAndDropLog) {
  auto s = ParseSpdSummary(
      "{\"StartFrame\": 128, \"EndFrame\": 658, \"CameraParameter\": {}, "
      "\"FrameDropIDLog\": {\"21334181\": [400, 200], \"21334237\": null}}",
      "s.json");
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->start_frame, 128);
  EXPECT_EQ(s->end_frame, 658);
  EXPECT_EQ(s->frame_drops.at("21334181"), (std::vector<int64_t>{200, 400}));
  EXPECT_TRUE(s->frame_drops.at("21334237").empty());
  EXPECT_FALSE(ParseSpdSummary("{\"FrameDropIDLog\": {\"1\": [\"a\"]}}", "s.json").ok());
  EXPECT_FALSE(ParseSpdSummary("{\"StartFrame\": \"x\"}", "s.json").ok());
}

NpyArray<double> Pattern(int64_t frames, int64_t views, int64_t points) {
  NpyArray<double> k;
  k.shape = {frames, views, points, 3};
  k.data.resize(static_cast<size_t>(frames * views * points * 3));
  for (size_t i = 0; i < k.data.size(); ++i) k.data[i] = 0.1 * static_cast<double>(i) + 1.0 / 3;
  k.at(0, 0, 5, 0) = NAN;  // SPD's missing detections
  k.at(0, 0, 5, 1) = NAN;
  return k;
}

TEST(SpdImport, ExportThenImportRoundTripsWithDroppedFrames) {
  TempDir dir;
  SpdImportOptions o;
  o.instrument = "cello";
  o.human_dir = dir / "human";
  o.instrument_dir = dir / "cello";
  o.serials = {"21334181", "21334237"};
  o.frame_first = 3;
  o.frame_last = 6;
  o.frame_drops = {{"21334237", {2, 5}}};
  NpyArray<double> k = Pattern(4, 2, 142);
  const double nan = NAN;
  for (int p = 0; p < 142; ++p) {
    for (int c = 0; c < 3; ++c) k.at(2, 1, p, c) = nan;  // global 5 dropped by 21334237
  }
  ASSERT_TRUE(ExportSpdKeypoints(o, k).ok());
  // Global 6 of camera 21334237 is its own frame 4 (drops 2 and 5 came before).
  EXPECT_TRUE(FileExists(dir / "human/21334237/4.json"));
  EXPECT_TRUE(FileExists(dir / "cello/21334237/4.json"));
  EXPECT_FALSE(FileExists(dir / "human/21334237/6.json"));
  EXPECT_TRUE(FileExists(dir / "human/21334181/6.json"));
  const auto text = ReadFileToString(dir / "human/21334181/3.json");
  ASSERT_TRUE(text.ok());
  EXPECT_NE(text->find("NaN"), std::string::npos);
  SpdImportReport report;
  auto back = ImportSpdKeypoints(o, &report);
  ASSERT_TRUE(back.ok()) << back.status().message();
  ASSERT_EQ(back->shape, k.shape);
  for (size_t i = 0; i < k.data.size(); ++i) {
    if (std::isnan(k.data[i])) {
      EXPECT_TRUE(std::isnan(back->data[i])) << i;
    } else {
      EXPECT_EQ(back->data[i], k.data[i]) << i;  // %.17g round-trips doubles exactly
    }
  }
  EXPECT_EQ(report.frames_dropped, 1);
  EXPECT_EQ(report.files_read, 14);
  EXPECT_EQ(report.files_missing, 0);
}

TEST(SpdImport, ViolinFullRowsAndMissingFiles) {
  TempDir dir;
  SpdImportOptions o;
  o.instrument = "violin";
  o.human_dir = dir / "kp";
  o.serials = {"1", "2"};
  o.frame_first = 1;
  o.frame_last = 2;
  const NpyArray<double> k = Pattern(2, 2, 140);
  ASSERT_TRUE(ExportSpdKeypoints(o, k).ok());
  std::filesystem::remove(dir / "kp/2/2.json");
  SpdImportReport report;
  auto back = ImportSpdKeypoints(o, &report);
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(report.files_missing, 1);
  EXPECT_TRUE(std::isnan(back->at(1, 1, 0, 0)));
  EXPECT_EQ(back->at(1, 0, 139, 2), k.at(1, 0, 139, 2));
  o.require_all_files = true;
  auto strict = ImportSpdKeypoints(o);
  ASSERT_FALSE(strict.ok());
  EXPECT_NE(strict.status().message().find("2.json"), std::string::npos);
}

TEST(SpdImport, WrongRowCountsAndOptionsAreErrors) {
  TempDir dir;
  ASSERT_TRUE(MakeDirectories(dir / "kp/7").ok());
  ASSERT_TRUE(AtomicWriteFile(dir / "kp/7/1.json", "[[1, 2, 3], [4, 5, 6]]").ok());
  SpdImportOptions o;
  o.human_dir = dir / "kp";
  o.serials = {"7"};
  auto r = ImportSpdKeypoints(o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("2 rows"), std::string::npos);
  ASSERT_TRUE(AtomicWriteFile(dir / "kp/7/1.json", "[[1, 2, 3]").ok());
  EXPECT_FALSE(ImportSpdKeypoints(o).ok());
  o.instrument = "lute";
  EXPECT_FALSE(o.Validate().ok());
  o.instrument = "cello";
  o.frame_last = 0;
  EXPECT_FALSE(o.Validate().ok());
  o.frame_last = 1;
  o.serials.clear();
  EXPECT_FALSE(o.Validate().ok());
}

}  // namespace
}  // namespace arco
