#include "arco/refine/method_result.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "arco/hand/kinematics.h"
#include "arco/mocap/capture.h"
#include "arco/mocap/keypoint_layout.h"
#include "arco/refine/refine.h"
#include "arco/refine/test_scene.h"
#include "arco/util/file_io.h"
#include "arco/util/test_dir.h"

namespace arco::refine {
namespace {

SpdSources SourcesFor(const testing::Scene& scene) {
  SpdSources s;
  s.instrument = scene.input.instrument;
  s.hand_model = scene.input.hand_model;
  const int64_t frames = static_cast<int64_t>(scene.input.pitch.size());
  const int64_t points = 133 + static_cast<int64_t>(scene.model->keypoint_names().size());
  s.base_points_mm.shape = {frames, points, 3};
  s.base_points_mm.data.assign(static_cast<size_t>(frames * points * 3), 0.0);
  for (size_t i = 0; i < s.base_points_mm.data.size(); ++i) s.base_points_mm.data[i] = 0.25 * i;
  s.strings_in_world_mm = scene.input.strings_in_world_mm;
  return s;
}

TEST(BuildSpdPoints, SpdLayoutWithStringsContactAndPlayingFinger) {
  for (InstrumentKind kind : {InstrumentKind::kCello, InstrumentKind::kViolin}) {
    const testing::Scene scene = testing::MakeScene(kind, {{0, 0, 0, 3}, {2, 3, 4, 10}});
    RefineOptions o;
    const RefineResult r = Refine(scene.input, o);
    const SpdSources sources = SourcesFor(scene);
    const NpyArray<double> a = BuildSpdPoints(sources, r.hand, &r.contacts);
    const KeypointLayout* layout = FindKeypointLayout(SpdContactLayoutName(*scene.model));
    ASSERT_NE(layout, nullptr);
    ASSERT_EQ(a.shape, (std::vector<int64_t>{13, layout->size(), 3}));
    EXPECT_EQ(layout->size(), kind == InstrumentKind::kCello ? 155 : 153);
    const int extra = layout->Find("string4_top");
    ASSERT_EQ(extra, kind == InstrumentKind::kCello ? 142 : 140);
    auto at = [&](int f, int p) {
      return Eigen::Vector3d(a.at(f, p, 0), a.at(f, p, 1), a.at(f, p, 2));
    };
    // Body and instrument points come through; the left hand is the refined one.
    EXPECT_EQ(a.at(5, 0, 1), sources.base_points_mm.at(5, 0, 1));
    EXPECT_EQ(a.at(5, 135, 2), sources.base_points_mm.at(5, 135, 2));
    const hand::HandPointsMm fk = hand::ForwardKinematics(scene.input.hand_model, *r.hand[5]);
    EXPECT_EQ(at(5, 91 + 12), fk[12]);
    // Strings lowest first, (nut, bridge).
    const auto& strings = scene.input.strings_in_world_mm[5];
    EXPECT_EQ(at(5, extra), strings[3].nut);
    EXPECT_EQ(at(5, extra + 1), strings[3].bridge);
    EXPECT_EQ(at(5, extra + 7), strings[0].bridge);
    // Contact and the playing finger (3: ring) on pressed frames, NaN on rests.
    ASSERT_TRUE(r.contacts[5].pressed());
    EXPECT_EQ(at(5, extra + 8), r.contacts[5].point_in_world_mm);
    EXPECT_EQ(at(5, extra + 9), fk[hand::KeypointIndex(hand::Finger::kRing, 0)]);
    EXPECT_EQ(at(5, extra + 12), fk[hand::TipKeypoint(hand::Finger::kRing)]);
    EXPECT_LT((at(5, extra + 12) - at(5, extra + 8)).norm(), 1.0);
    EXPECT_TRUE(std::isnan(a.at(1, extra + 8, 0)));
    EXPECT_TRUE(std::isnan(a.at(1, extra + 12, 0)));
    // Vision: strings, no contact.
    const NpyArray<double> v = BuildSpdPoints(sources, scene.input.vision_hand, nullptr);
    EXPECT_TRUE(std::isnan(v.at(5, extra + 8, 0)));
    EXPECT_EQ(v.at(5, extra, 0), strings[3].nut.x());
  }
}

TEST(HandParams, RoundTrip) {
  const testing::Scene scene = testing::MakeScene(InstrumentKind::kCello, {{2, 1, 2, 4}});
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

TEST(WriteMethodResult, WritesTheFolderAndTheManifestAndReadsBack) {
  arco::testing::TempDir dir;
  const testing::Scene scene =
      testing::MakeScene(InstrumentKind::kCello, {{0, 0, 0, 2}, {2, 2, 3, 8}});
  RefineOptions o;
  const RefineResult r = Refine(scene.input, o);
  MethodOutput out;
  out.method = "arco";
  out.layout = SpdContactLayoutName(*scene.model);
  out.points3d = BuildSpdPoints(SourcesFor(scene), r.hand, &r.contacts);
  out.hands = r.hand;
  out.contacts = r.contacts;
  out.fingering = r.fingering;
  out.summary = {{"pressed", r.summary.pressed}};
  ASSERT_TRUE(WriteMethodResult(dir.path(), out).ok());
  const auto manifest = ReadResultManifest(dir.path());
  ASSERT_TRUE(manifest.ok()) << manifest.status().message();
  EXPECT_EQ((*manifest)["stages"]["arco"]["layout"], "spd_cello_contact");
  EXPECT_EQ((*manifest)["stages"]["arco"]["summary"]["pressed"], 8);
  const auto points = ReadResultPoints3d(dir.path(), "arco");
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
  ASSERT_TRUE(WriteMethodResult(dir.path(), out).ok());
  const auto m2 = ReadResultManifest(dir.path());
  EXPECT_TRUE((*m2)["stages"].contains("arco"));
  EXPECT_FALSE(FileExists(dir / "vision/contacts.csv"));
}

TEST(WriteMethodResult, FailsWholeWithoutPartialOutput) {
  arco::testing::TempDir dir;
  ASSERT_TRUE(AtomicWriteFile(dir / "file", "x").ok());
  MethodOutput out;
  out.method = "arco";
  EXPECT_FALSE(WriteMethodResult(dir / "file", out).ok());  // the result folder is a file
  ASSERT_TRUE(AtomicWriteFile(dir / "result.json", "{\"format\": \"other\"}").ok());
  const Status s = WriteMethodResult(dir.path(), out);
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

}  // namespace
}  // namespace arco::refine
