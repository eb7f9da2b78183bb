// The result folder's readers and writers: each writes and reads back, malformed files
// are errors that name the file and line, and folders are written whole or not at all.
#include "arco/pipeline/result_folder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "arco/hand/kinematics.h"
#include "arco/refine/method_result.h"
#include "arco/refine/refine.h"
#include "arco/refine/test_scene.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/util/file_io.h"
#include "arco/util/test_dir.h"

namespace arco::pipeline {
namespace {

using arco::testing::TempDir;

CaptureManifest SampleManifest() {
  CaptureManifest m;
  m.name = "cello_1113_scale";
  m.instrument = "cello";
  m.fps = 30;
  m.frame_first = 128;
  m.frame_count = 4;
  m.tuning_a4_hz = 442;
  m.calibration = "calibration.xml";
  m.audio = "audio.wav";
  m.audio_offset_s = 1.25;
  m.keypoints2d = "keypoints2d.npy";
  m.layout = "spd_cello";
  m.cameras = {{"cam0", "21334181", "videos/21334181.avi", {129, 300}},
               {"cam1", "21334237", "", {}}};
  return m;
}

refine::SpdSources SourcesFor(const refine::testing::Scene& scene) {
  refine::SpdSources s;
  s.instrument = scene.input.instrument;
  s.hand_model = scene.input.hand_model;
  const int64_t frames = static_cast<int64_t>(scene.input.pitch.size());
  const int64_t points =
      wholebody::kNumPoints + static_cast<int64_t>(scene.model->keypoint_names().size());
  s.base_points_mm.shape = {frames, points, 3};
  s.base_points_mm.data.assign(static_cast<size_t>(frames * points * 3), 0.0);
  for (size_t i = 0; i < s.base_points_mm.data.size(); ++i) s.base_points_mm.data[i] = 0.25 * i;
  s.strings_in_world_mm = scene.input.strings_in_world_mm;
  return s;
}

TEST(ResultFolder, TriangulationWritesStageFolderAndKeepsOtherStages) {
  TempDir dir;
  const std::string result_dir = dir / "result";
  ASSERT_TRUE(MakeDirectories(result_dir).ok());
  ASSERT_TRUE(
      WriteJsonFile(result_dir + "/result.json",
                    Json{{"format", "arco-result"}, {"stages", {{"arco", {{"dir", "arco"}}}}}})
          .ok());
  const CaptureManifest m = SampleManifest();
  SequenceTriangulation raw;
  raw.points3d.shape = {4, 142, 3};
  raw.points3d.data.assign(4 * 142 * 3, 1.0);
  raw.rms_reprojection_px.shape = {4, 142};
  raw.rms_reprojection_px.data.assign(4 * 142, 2.0f);
  raw.num_inliers.shape = raw.num_views.shape = {4, 142};
  raw.num_inliers.data.assign(4 * 142, 2);
  raw.num_views.data.assign(4 * 142, 2);
  raw.inlier_mask.shape = {4, 142, 2};
  raw.inlier_mask.data.assign(4 * 142 * 2, 1);
  TriangulationRecord info;
  info.capture_dir = "cap";
  info.units = "m";
  info.summary = Summarize(raw);
  ASSERT_TRUE(ResultFolder(result_dir)
                  .WriteTriangulation(m, *FindKeypointLayout("spd_cello"), raw, raw.points3d, info)
                  .ok());
  auto manifest = ResultFolder(result_dir).ReadManifest();
  ASSERT_TRUE(manifest.ok());
  EXPECT_TRUE((*manifest)["stages"].contains("arco"));
  EXPECT_EQ((*manifest)["stages"]["triangulation"]["summary"]["triangulated"], 568);
  EXPECT_EQ((*manifest)["keypoint_names"].size(), 142u);
  auto points = ResultFolder(result_dir).ReadPoints3d(kTriangulationStage);
  ASSERT_TRUE(points.ok());
  EXPECT_EQ(points->shape, raw.points3d.shape);
  for (const char* f : {"points3d_raw.npy",
                        "reprojection_rms_px.npy",
                        "inlier_count.npy",
                        "view_count.npy",
                        "inlier_mask.npy"}) {
    EXPECT_TRUE(FileExists(result_dir + "/triangulation/" + f)) << f;
  }
  int entries = 0;
  for (const auto& e : std::filesystem::directory_iterator(result_dir)) {
    (void)e;
    ++entries;
  }
  EXPECT_EQ(entries, 2);  // result.json and triangulation/, no temporary folder left
}

TEST(HandParams, RoundTrip) {
  const refine::testing::Scene scene =
      refine::testing::MakeScene(InstrumentKind::kCello, {{2, 1, 2, 4}});
  std::vector<std::optional<hand::HandPose>> hands = scene.input.vision_hand;
  hands[2].reset();
  const auto back = HandsFromParams(HandParams(hands), "x");
  ASSERT_TRUE(back.ok());
  ASSERT_EQ(back->size(), 4u);
  EXPECT_FALSE((*back)[2].has_value());
  const auto p0 = hand::ForwardKinematics(scene.input.hand_model, *hands[0]);
  const auto q0 = hand::ForwardKinematics(scene.input.hand_model, *(*back)[0]);
  for (int k = 0; k < 21; ++k) EXPECT_LT((p0[k] - q0[k]).norm(), 1e-9);
  NpyArray<double> bad;
  bad.shape = {3, 25};
  bad.data.assign(75, 0.0);
  EXPECT_FALSE(HandsFromParams(bad, "bad.npy").ok());
}

TEST(ResultFolder, WriteMethodWritesTheFolderAndTheManifestAndReadsBack) {
  arco::testing::TempDir dir;
  const refine::testing::Scene scene =
      refine::testing::MakeScene(InstrumentKind::kCello, {{0, 0, 0, 2}, {2, 2, 3, 8}});
  refine::RefineOptions o;
  const refine::RefineResult r = refine::Refine(scene.input, o);
  MethodRecord out;
  out.method = "arco";
  out.layout = refine::SpdContactLayoutName(*scene.model);
  out.points3d = refine::BuildSpdPoints(SourcesFor(scene), r.hand, &r.contacts);
  out.hands = r.hand;
  out.contacts = r.contacts;
  out.fingering = r.fingering;
  out.summary = r.summary;
  ASSERT_TRUE(ResultFolder(dir.path()).WriteMethod(out).ok());
  const auto manifest = ResultFolder(dir.path()).ReadManifest();
  ASSERT_TRUE(manifest.ok()) << manifest.status().message();
  EXPECT_EQ((*manifest)["stages"]["arco"]["layout"], "spd_cello_contact");
  EXPECT_EQ((*manifest)["stages"]["arco"]["summary"]["pressed"], 8);
  const auto points = ResultFolder(dir.path()).ReadPoints3d("arco");
  ASSERT_TRUE(points.ok());
  EXPECT_EQ(points->shape, out.points3d.shape);
  const auto rows = ReadContactsCsv(dir / "arco/contacts.csv");
  ASSERT_TRUE(rows.ok()) << rows.status().message();
  ASSERT_EQ(rows->size(), 10u);
  EXPECT_EQ((*rows)[0].state, "rest");
  EXPECT_EQ((*rows)[4].state, "pressed");
  EXPECT_EQ((*rows)[4].string, 2);
  EXPECT_EQ((*rows)[4].finger, 2);
  EXPECT_EQ((*rows)[4].point_mm, r.contacts[4].point_in_world_mm);  // exact round trip
  EXPECT_TRUE(FileExists(dir / "arco/fingering.csv"));
  // A second method keeps the first in the manifest; vision has no contacts.
  out.method = "vision";
  out.contacts.clear();
  ASSERT_TRUE(ResultFolder(dir.path()).WriteMethod(out).ok());
  const auto m2 = ResultFolder(dir.path()).ReadManifest();
  EXPECT_TRUE((*m2)["stages"].contains("arco"));
  EXPECT_FALSE(FileExists(dir / "vision/contacts.csv"));
}

TEST(ResultFolder, WriteMethodFailsWholeWithoutPartialOutput) {
  arco::testing::TempDir dir;
  ASSERT_TRUE(AtomicWriteFile(dir / "file", "x").ok());
  MethodRecord out;
  out.method = "arco";
  EXPECT_FALSE(ResultFolder(dir / "file").WriteMethod(out).ok());  // the result folder is a file
  ASSERT_TRUE(AtomicWriteFile(dir / "result.json", "{\"format\": \"other\"}").ok());
  const Status s = ResultFolder(dir.path()).WriteMethod(out);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("result.json"), std::string::npos) << s.message();
  EXPECT_FALSE(FileExists(dir / "arco"));
}

TEST(ReadContactsCsv, MalformedFilesNameTheFileAndLine) {
  arco::testing::TempDir dir;
  EXPECT_FALSE(ReadContactsCsv(dir / "missing.csv").ok());
  ASSERT_TRUE(AtomicWriteFile(dir / "a.csv", "frame,state\n").ok());
  EXPECT_FALSE(ReadContactsCsv(dir / "a.csv").ok());
  const std::string header = std::string(kContactsCsvHeader) + "\n";
  ASSERT_TRUE(AtomicWriteFile(dir / "b.csv", header + "0,pressed,,1,2,0,1,2\n").ok());
  const auto b = ReadContactsCsv(dir / "b.csv");
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.status().message().find("b.csv:2"), std::string::npos) << b.status().message();
  ASSERT_TRUE(AtomicWriteFile(dir / "c.csv", header + "0,pressed,,1,2,0,x,2,3,4,5,6,7,8,0\n").ok());
  EXPECT_FALSE(ReadContactsCsv(dir / "c.csv").ok());
  ASSERT_TRUE(AtomicWriteFile(dir / "d.csv", header + "0,flying,,1,2,0,1,2,3,4,5,6,7,8,0\n").ok());
  EXPECT_FALSE(ReadContactsCsv(dir / "d.csv").ok());
  ASSERT_TRUE(AtomicWriteFile(dir / "e.csv", header + "0,pressed,,9,2,0,1,2,3,4,5,6,7,8,0\n").ok());
  EXPECT_FALSE(ReadContactsCsv(dir / "e.csv").ok());
  ASSERT_TRUE(AtomicWriteFile(dir / "f.csv",
                              header + "0,rest,unvoiced,0,0,-1,nan,nan,nan,nan,0,0.1,nan,nan,0\n")
                  .ok());
  const auto f = ReadContactsCsv(dir / "f.csv");
  ASSERT_TRUE(f.ok()) << f.status().message();
  EXPECT_TRUE(std::isnan((*f)[0].point_mm.x()));
}

TEST(ReadContactsCsv, ReadsTruthContactFilesByColumnName) {
  arco::testing::TempDir dir;
  // synth's truth/contact.csv: other columns, other order, "open_string" for open strings.
  ASSERT_TRUE(AtomicWriteFile(dir / "contact.csv",
                              "frame,time_s,state,string,finger,note,f0_hz,contact_x_mm,"
                              "contact_y_mm,contact_z_mm\n"
                              "0,0.000000,rest,0,0,-1,0.0000,nan,nan,nan\n"
                              "1,0.033333,pressed,2,3,0,220.0000,1.5000,-2.0000,3.2500\n"
                              "2,0.066667,open_string,0,0,1,220.0000,-nan,-nan,-nan\n")
                  .ok());
  const auto rows = ReadContactsCsv(dir / "contact.csv");
  ASSERT_TRUE(rows.ok()) << rows.status().message();
  ASSERT_EQ(rows->size(), 3u);
  EXPECT_EQ((*rows)[1].string, 2);
  EXPECT_EQ((*rows)[1].finger, 3);
  EXPECT_EQ((*rows)[1].point_mm, Eigen::Vector3d(1.5, -2.0, 3.25));
  EXPECT_EQ((*rows)[2].state, "open_string");
  EXPECT_TRUE(std::isnan((*rows)[2].point_mm.x()));
  // A pressed string needs a finger and a point.
  ASSERT_TRUE(AtomicWriteFile(dir / "bad.csv",
                              "frame,string,finger,contact_x_mm,contact_y_mm,contact_z_mm\n"
                              "0,1,0,1,2,3\n")
                  .ok());
  const auto bad = ReadContactsCsv(dir / "bad.csv");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("bad.csv:2"), std::string::npos);
}

}  // namespace
}  // namespace arco::pipeline
