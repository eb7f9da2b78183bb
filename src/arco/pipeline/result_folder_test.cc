// The result folder's readers and writers: each writes and reads back, malformed files
// are errors that name the file and line, and folders are written whole or not at all.
#include "arco/pipeline/result_folder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "arco/hand/kinematics.h"
#include "arco/mocap/sample_manifest.h"
#include "arco/refine/contacts_csv.h"
#include "arco/refine/method_result.h"
#include "arco/refine/refine.h"
#include "arco/refine/test_scene.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"

namespace arco::pipeline {
namespace {

using arco::testing::SampleManifest;
using arco::testing::TempDir;

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

// A new triangulation removes the stages made from the old one (result_inputs_test.cc
// tries every stage).
TEST(ResultFolder, TriangulationWritesStageFolderAndRemovesLaterStages) {
  TempDir dir;
  const std::string result_dir = dir / "result";
  ASSERT_TRUE(MakeDirectories(result_dir + "/arco").ok());
  ASSERT_TRUE(AtomicWriteFile(result_dir + "/arco/points3d.npy", "old").ok());
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
  // As a user gives it: relative to the working folder.
  info.capture_dir = std::filesystem::path(dir / "captures/cap/")
                         .lexically_relative(std::filesystem::current_path())
                         .string();
  info.units = "m";
  info.summary = Summarize(raw);
  const auto removed =
      ResultFolder(result_dir)
          .WriteTriangulation(m, *FindKeypointLayout("spd_cello"), raw, raw.points3d, info);
  ASSERT_TRUE(removed.ok()) << removed.status().message();
  EXPECT_EQ(*removed, std::vector<std::string>{"arco"});
  auto manifest = ResultFolder(result_dir).ReadManifest();
  ASSERT_TRUE(manifest.ok());
  EXPECT_FALSE((*manifest)["stages"].contains("arco"));
  EXPECT_EQ((*manifest)["removed_stages"], Json::array({"arco"}));
  EXPECT_FALSE(FileExists(result_dir + "/arco"));
  EXPECT_EQ((*manifest)["stages"]["triangulation"]["summary"]["triangulated"], 568);
  EXPECT_EQ((*manifest)["keypoint_names"].size(), 142u);
  // The capture path is relative to the result folder, and read back against it.
  EXPECT_EQ((*manifest)["capture"], "../captures/cap");
  auto header = ResultFolder(result_dir).ReadHeader();
  ASSERT_TRUE(header.ok());
  EXPECT_EQ(header->capture_dir, dir / "captures/cap");
  // An absolute path stays absolute.
  info.capture_dir = dir / "captures/cap/";
  ASSERT_TRUE(ResultFolder(result_dir)
                  .WriteTriangulation(m, *FindKeypointLayout("spd_cello"), raw, raw.points3d, info)
                  .ok());
  EXPECT_EQ((*ResultFolder(result_dir).ReadManifest())["capture"], dir / "captures/cap");
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
  const auto rows = refine::ReadContactsCsv(dir / "arco/contacts.csv");
  ASSERT_TRUE(rows.ok()) << rows.status().message();
  ASSERT_EQ(rows->size(), 10u);
  EXPECT_EQ((*rows)[0].state, "rest");
  EXPECT_EQ((*rows)[4].state, "pressed");
  EXPECT_EQ((*rows)[4].string, 2);
  EXPECT_EQ((*rows)[4].finger, 2);
  EXPECT_EQ((*rows)[4].point_mm, r.contacts[4].point_in_world_mm);  // exact round trip
  EXPECT_TRUE(FileExists(dir / "arco/fingering.csv"));
  // fingering.csv reads back (%.17g: exact).
  const auto fingering = ResultFolder(dir.path()).ReadFingering("arco");
  ASSERT_TRUE(fingering.ok()) << fingering.status().message();
  ASSERT_EQ(fingering->size(), r.fingering.size());
  ASSERT_FALSE(r.fingering.empty());
  for (size_t i = 0; i < r.fingering.size(); ++i) {
    const refine::NoteFingering &a = (*fingering)[i], &b = r.fingering[i];
    EXPECT_EQ(a.note, b.note);
    EXPECT_EQ(a.first_frame, b.first_frame);
    EXPECT_EQ(a.last_frame, b.last_frame);
    EXPECT_EQ(a.onset_s, b.onset_s);
    EXPECT_EQ(a.f0_hz, b.f0_hz);
    EXPECT_EQ(a.midi_note, b.midi_note);
    EXPECT_EQ(a.cents_off, b.cents_off);
    EXPECT_EQ(a.state, b.state);
    EXPECT_EQ(a.string, b.string);
    EXPECT_EQ(a.finger, b.finger);
    EXPECT_EQ(std::isnan(a.from_nut_mm), std::isnan(b.from_nut_mm));
    if (!std::isnan(b.from_nut_mm)) {
      EXPECT_EQ(a.from_nut_mm, b.from_nut_mm);
    }
    EXPECT_EQ(a.pressed_frames, b.pressed_frames);
  }
  // A damaged row names the file and line; a method without the file has no notes.
  {
    auto text = ReadFileToString(dir / "arco/fingering.csv");
    ASSERT_TRUE(text.ok());
    ASSERT_TRUE(AtomicWriteFile(dir / "arco/fingering.csv", *text + "9,x,3\n").ok());
    const auto bad = ResultFolder(dir.path()).ReadFingering("arco");
    ASSERT_FALSE(bad.ok());
    EXPECT_NE(bad.status().message().find("fingering.csv:"), std::string::npos)
        << bad.status().message();
    EXPECT_NE(bad.status().message().find(": expected "), std::string::npos)
        << bad.status().message();
    ASSERT_TRUE(AtomicWriteFile(dir / "arco/fingering.csv", *text).ok());
    const auto none = ResultFolder(dir.path()).ReadFingering("vision");
    ASSERT_TRUE(none.ok());
    EXPECT_TRUE(none->empty());
  }
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

// `arco run`'s one ResultFolder: result.json read at most once, then held as its last
// committed write made it (shared by the copies), never read back; a failed write leaves
// it as it was. A plain ResultFolder reads the file.
TEST(ResultFolder, ExclusiveHoldsTheManifestItReadOrCommitted) {
  TempDir dir;
  PitchRecord pitch;
  pitch.a4_hz = 442;
  {
    const std::string path = dir / "failed/result.json";
    ASSERT_TRUE(MakeDirectories(dir / "failed").ok());
    // A later stage that names a folder outside the result: writing the pitch fails whole.
    const Json escaping = {{"format", "arco-result"},
                           {"stages", {{"arco", {{"dir", "../escape"}}}}}};
    ASSERT_TRUE(WriteJsonFile(path, escaping).ok());
    const ResultFolder held = ResultFolder::Exclusive(dir / "failed");
    const ResultFolder copy = held;
    EXPECT_FALSE(held.WritePitch(pitch).ok());
    EXPECT_FALSE(FileExists(dir / "failed/pitch.csv"));
    ASSERT_TRUE(WriteJsonFile(path, Json{{"format", "arco-result"}}).ok());  // not read again
    const auto m = copy.ReadManifest();
    ASSERT_TRUE(m.ok()) << m.status().message();
    EXPECT_EQ(*m, escaping);
  }
  const ResultFolder held = ResultFolder::Exclusive(dir / "ok");
  ASSERT_TRUE(held.WritePitch(pitch).ok());
  ASSERT_TRUE(WriteJsonFile(dir / "ok/result.json", Json{{"format", "arco-result"}}).ok());
  const ResultFolder copy = held;
  const auto m = copy.ReadManifest();
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ((*m)["stages"]["pitch"]["a4_hz"], 442);
  const auto disk = ResultFolder(dir / "ok").ReadManifest();
  ASSERT_TRUE(disk.ok()) << disk.status().message();
  EXPECT_FALSE(disk->contains("stages"));
}

}  // namespace
}  // namespace arco::pipeline
