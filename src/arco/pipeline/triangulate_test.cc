#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "arco/calibration/calibration_file.h"
#include "arco/capture/label_views.h"
#include "arco/pipeline/result_folder.h"
#include "arco/pipeline/triangulate_stage.h"
#include "arco/testing/synthetic_views.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"

namespace arco::pipeline {
namespace {

using arco::testing::TempDir;

const std::string kSpd = std::string(ARCO_SHARED_DATA_DIR) + "/spd/";
const char* kSerials[] = {"21334181", "21334190", "21334211", "21334237"};

capture::LabelViewsOptions RealLabels() {
  capture::LabelViewsOptions o;
  o.calibration = kSpd + "cello_1113_scale_camera.xml";
  for (const char* s : kSerials) {
    o.views.emplace_back(s, kSpd + "labels_frame128/cello_1113_scale_" + s + "_128.json");
  }
  return o;
}

// The acceptance test of issue 2 on the real frame-128 labels.
TEST(TriangulateLabelViews, RealSpdLabelsMeetTheReprojectionAndStringSideBars) {
  auto r = capture::TriangulateLabelViews(RealLabels());
  ASSERT_TRUE(r.ok()) << r.status().message();
  const double rms = (*r)["rms_reprojection_px"];
  EXPECT_LE(rms, 2.6);
  EXPECT_GT(rms, 1.0);  // labels are not perfect: a near-zero RMS would mean a bug
  EXPECT_EQ((*r)["points"].size(), 9u);
  EXPECT_TRUE((*r)["not_triangulated"].empty());
  const Json& lengths = (*r)["lengths"];
  EXPECT_LT(lengths["difference_percent"].get<double>(), 1.0);
  // One Metashape unit is about 2.02 m in this session (spd/README.md): ~0.344 units.
  EXPECT_NEAR(lengths["nut_l-bridge_l"].get<double>(), 0.344, 0.01);
  for (const Json& p : (*r)["points"]) {
    EXPECT_EQ(p["num_views"], 4) << p["name"];
    EXPECT_GE(p["inlier_views"].size(), 3u) << p["name"];
  }
  std::printf("frame 128: RMS %.3f px, string sides %.5f / %.5f (%.2f%%)\n",
              rms,
              lengths["nut_l-bridge_l"].get<double>(),
              lengths["nut_r-bridge_r"].get<double>(),
              lengths["difference_percent"].get<double>());
}

TEST(TriangulateLabelViews, IgnoringDistortionRaisesTheError) {
  capture::LabelViewsOptions o = RealLabels();
  auto with = capture::TriangulateLabelViews(o);
  o.ignore_distortion = true;
  auto without = capture::TriangulateLabelViews(o);
  ASSERT_TRUE(with.ok() && without.ok());
  const double a = (*with)["rms_reprojection_px"], b = (*without)["rms_reprojection_px"];
  EXPECT_GT(b, a + 0.5);  // DOMAIN.md: about 3.4 px without, 2.4-2.5 px with
  EXPECT_NEAR(b, 3.4, 0.4);
  EXPECT_FALSE((*without)["distortion_modelled"].get<bool>());
}

TEST(TriangulateLabelViews, SameResultWithCameraNamesAndSpdJsonCalibration) {
  // SPD JSON names cameras camK: 21334181 = cam0, 21334190 = cam18, 21334211 = cam19,
  // 21334237 = cam1 (spd/README.md). Its converter dropped the distortion, which arco
  // reads back, so the results must agree with the XML.
  capture::LabelViewsOptions o = RealLabels();
  o.calibration = kSpd + "cello_1113_scale_camera.json";
  const char* names[] = {"cam0", "cam18", "cam19", "cam1"};
  for (int i = 0; i < 4; ++i) o.views[i].first = names[i];
  auto json = capture::TriangulateLabelViews(o);
  auto xml = capture::TriangulateLabelViews(RealLabels());
  ASSERT_TRUE(json.ok()) << json.status().message();
  ASSERT_TRUE(xml.ok());
  EXPECT_NEAR((*json)["rms_reprojection_px"].get<double>(),
              (*xml)["rms_reprojection_px"].get<double>(),
              0.05);
}

TEST(TriangulateLabelViews, ViewOrderDoesNotChangeThePoints) {
  capture::LabelViewsOptions o = RealLabels();
  auto a = capture::TriangulateLabelViews(o);
  std::reverse(o.views.begin(), o.views.end());
  auto b = capture::TriangulateLabelViews(o);
  ASSERT_TRUE(a.ok() && b.ok());
  for (const Json& pa : (*a)["points"]) {
    bool found = false;
    for (const Json& pb : (*b)["points"]) {
      if (pb["name"] != pa["name"]) continue;
      found = true;
      EXPECT_EQ(pa["xyz"], pb["xyz"]) << pa["name"];
    }
    EXPECT_TRUE(found);
  }
}

TEST(TriangulateLabelViews, ScaleToInstrumentReportsMillimetres) {
  capture::LabelViewsOptions o = RealLabels();
  o.reference_string_length_mm = 695;
  auto r = capture::TriangulateLabelViews(o);
  ASSERT_TRUE(r.ok());
  const Json& l = (*r)["lengths"];
  EXPECT_NEAR(0.5 * (l["nut_l-bridge_l_mm"].get<double>() + l["nut_r-bridge_r_mm"].get<double>()),
              695.0,
              1e-9);
  // DOMAIN.md section 5: about 23.9 mm at the nut and 48.2 mm at the bridge.
  EXPECT_NEAR(l["nut_l-nut_r_mm"].get<double>(), 23.9, 3.0);
  EXPECT_NEAR(l["bridge_l-bridge_r_mm"].get<double>(), 48.2, 4.0);
}

void ExpectError(const capture::LabelViewsOptions& o, const std::string& words) {
  auto r = capture::TriangulateLabelViews(o);
  ASSERT_FALSE(r.ok()) << "expected an error about " << words;
  EXPECT_NE(r.status().message().find(words), std::string::npos) << r.status().message();
  EXPECT_EQ(r.status().message().find('\n'), std::string::npos);  // one line
}

TEST(TriangulateLabelViews, BadInputsGiveOneLineErrors) {
  TempDir dir;
  capture::LabelViewsOptions o = RealLabels();
  o.views.resize(1);
  ExpectError(o, "at least two");

  o = RealLabels();
  o.views[1].first = "99999999";
  ExpectError(o, "camera \"99999999\" is not in");

  o = RealLabels();
  o.views[1].first = o.views[0].first;
  ExpectError(o, "twice");

  o = RealLabels();
  o.calibration = dir / "missing.xml";
  ExpectError(o, "missing.xml");

  ASSERT_TRUE(AtomicWriteFile(dir / "broken.xml", "<document><chunk>").ok());
  o.calibration = dir / "broken.xml";
  ExpectError(o, "broken.xml");

  o = RealLabels();
  o.views[2].second = dir / "nope.json";
  ExpectError(o, "nope.json");

  ASSERT_TRUE(AtomicWriteFile(dir / "malformed.json", "{\"shapes\": [").ok());
  o.views[2].second = dir / "malformed.json";
  ExpectError(o, "malformed.json");

  const auto original = ReadFileToString(o.views[0].second);
  ASSERT_TRUE(original.ok());
  std::string nan_text = *original;
  nan_text.replace(nan_text.find("1350.0"), 6, "NaN");
  ASSERT_TRUE(AtomicWriteFile(dir / "nan.json", nan_text).ok());
  o = RealLabels();
  o.views[0].second = dir / "nan.json";
  ExpectError(o, "NaN");

  std::string size_text = *original;
  size_text.replace(size_text.find("\"imageWidth\": 2300"), 18, "\"imageWidth\": 2656");
  ASSERT_TRUE(AtomicWriteFile(dir / "size.json", size_text).ok());
  o.views[0].second = dir / "size.json";
  ExpectError(o, "image is 2656x2656");

  ASSERT_TRUE(AtomicWriteFile(dir / "empty.json", "{\"shapes\": []}").ok());
  o = RealLabels();
  o.views = {{kSerials[0], dir / "empty.json"}, {kSerials[1], dir / "empty.json"}};
  ExpectError(o, "no label");
}

// A synthetic capture folder with known truth, run end to end.
struct SyntheticCapture {
  Rig rig;
  NpyArray<double> truth;
};

SyntheticCapture WriteSyntheticCapture(const std::string& dir, int frames) {
  testing::SyntheticRigOptions ro;
  ro.num_cameras = 8;
  SyntheticCapture c;
  c.rig = testing::MakeSyntheticRig(ro);
  c.truth = testing::MakeSyntheticPoints(frames, 21, 5);
  testing::SyntheticDetectionOptions d;
  d.outlier_fraction = 0.05;
  d.missing_fraction = 0.1;
  NpyArray<double> k = testing::MakeSyntheticDetections(c.rig, c.truth, d);
  EXPECT_TRUE(MakeDirectories(dir).ok());
  EXPECT_TRUE(calibration::SaveCalibration(dir + "/rig.json", c.rig).ok());
  NpyArray<float> kf;
  kf.shape = k.shape;
  kf.data.assign(k.data.begin(), k.data.end());
  EXPECT_TRUE(WriteNpy(dir + "/keypoints2d.npy", kf).ok());
  CaptureManifest m;
  m.name = "synthetic";
  m.frame_first = 1;
  m.frame_count = frames;
  m.calibration = "rig.json";
  m.keypoints2d = "keypoints2d.npy";
  m.layout = "hand_21";
  for (const Camera& cam : c.rig.cameras) m.cameras.push_back({cam.name, cam.serial, "", {}});
  m.cameras[3].dropped_frames = {2};
  EXPECT_TRUE(WriteCaptureManifest(dir, m).ok());
  return c;
}

TEST(TriangulateCapture, SyntheticCaptureEndToEnd) {
  TempDir dir;
  const SyntheticCapture c = WriteSyntheticCapture(dir / "capture", 30);
  TriangulateStageOptions o;
  o.capture_dir = dir / "capture";
  o.result_dir = dir / "result";
  o.triangulation.num_threads = 2;
  struct Count : Progress {
    int64_t started = 0;
    std::atomic<int64_t> done{0};
    void SetTotal(int64_t n) override { started = n; }
    void Advance(int64_t n) override { done += n; }
  } progress;
  auto s = RunTriangulateStage(o, progress);
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(progress.started, 30);
  EXPECT_EQ(progress.done.load(), 30);
  EXPECT_EQ(s->triangulation.points, 30 * 21);
  EXPECT_EQ(s->triangulation.triangulated, 30 * 21);
  EXPECT_EQ(s->units, "m");
  auto points = ResultFolder(o.result_dir).ReadPoints3d(kTriangulationStage);
  ASSERT_TRUE(points.ok());
  double worst = 0;
  for (size_t i = 0; i < points->data.size(); ++i) {
    worst = std::max(worst, std::abs(points->data[i] - c.truth.data[i]));
  }
  EXPECT_LT(worst, 3e-3);
  auto mask = ReadNpy<uint8_t>(o.result_dir + "/triangulation/inlier_mask.npy");
  ASSERT_TRUE(mask.ok());
  for (int p = 0; p < 21; ++p) EXPECT_EQ(mask->at(1, p, 3), 0);  // frame 2 dropped by camera 3
}

TEST(TriangulateCapture, FiltersSmoothChosenGroupsOnly) {
  TempDir dir;
  WriteSyntheticCapture(dir / "capture", 40);
  TriangulateStageOptions o;
  o.capture_dir = dir / "capture";
  o.result_dir = dir / "result";
  o.filters.emplace_back("hand", *ParseFilterSpec("savgol:9:2"));
  ASSERT_TRUE(RunTriangulateStage(o).ok());
  auto raw = ReadNpy<double>(o.result_dir + "/triangulation/points3d_raw.npy");
  auto smooth = ResultFolder(o.result_dir).ReadPoints3d(kTriangulationStage);
  ASSERT_TRUE(raw.ok() && smooth.ok());
  EXPECT_NE(raw->data, smooth->data);
  auto manifest = ResultFolder(o.result_dir).ReadManifest();
  ASSERT_TRUE(manifest.ok());
  EXPECT_EQ((*manifest)["stages"]["triangulation"]["options"]["filters"][0]["filter"],
            "savgol:9:2");
  o.filters = {{"left_hand", *ParseFilterSpec("savgol:9:2")}};
  o.result_dir = dir / "result2";
  auto bad = RunTriangulateStage(o);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("left_hand"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(o.result_dir));  // nothing written on error
}

TEST(TriangulateCapture, BadCapturesAreErrorsWithoutOutput) {
  TempDir dir;
  WriteSyntheticCapture(dir / "capture", 3);
  TriangulateStageOptions o;
  o.capture_dir = dir / "capture";
  o.result_dir = dir / "result";
  // A camera the calibration lacks.
  auto m = ReadCaptureManifest(o.capture_dir);
  ASSERT_TRUE(m.ok());
  CaptureManifest edited = *m;
  edited.cameras[2].name = "ghost";
  edited.cameras[2].serial = "";
  ASSERT_TRUE(WriteCaptureManifest(o.capture_dir, edited).ok());
  auto r = RunTriangulateStage(o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("\"ghost\" is not in"), std::string::npos);
  // Keypoints of the wrong shape.
  edited = *m;
  edited.frame_count = 4;
  ASSERT_TRUE(WriteCaptureManifest(o.capture_dir, edited).ok());
  r = RunTriangulateStage(o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("keypoints2d.npy"), std::string::npos);
  // No manifest at all.
  o.capture_dir = dir / "nothing";
  r = RunTriangulateStage(o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("capture.json"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(o.result_dir));
}

}  // namespace
}  // namespace arco::pipeline

namespace arco::pipeline {
namespace {

// Cameras synced by sound (docs/formats.md): half the rig started 16 ms after the
// capture's zero and runs 50 ppm slow, so their frame g shows a bow moving at 1 m/s
// 16 mm further on. With cameras[].offset_s and drift_ppm in capture.json the stage
// triangulates every view at the same instant; without them, from moments apart.
TEST(TriangulateCapture, CamerasSyncedBySoundAreTriangulatedAtOneInstant) {
  constexpr int kFrames = 30;
  constexpr double kFps = 30, kOffsetS = 0.016, kDriftPpm = 50;
  testing::SyntheticRigOptions ro;
  ro.num_cameras = 8;
  const Rig rig = testing::MakeSyntheticRig(ro);
  // 21 points of a rigid stick moving along x at 1 m/s.
  const auto points_at = [](const std::vector<double>& times_s) {
    NpyArray<double> p;
    p.shape = {static_cast<int64_t>(times_s.size()), 21, 3};
    p.data.resize(times_s.size() * 21 * 3);
    for (size_t f = 0; f < times_s.size(); ++f) {
      for (int64_t i = 0; i < 21; ++i) {
        p.at(static_cast<int64_t>(f), i, 0) = -0.3 + 1.0 * times_s[f] + 0.01 * i;
        p.at(static_cast<int64_t>(f), i, 1) = 0.02 * i;
        p.at(static_cast<int64_t>(f), i, 2) = 1.0 + 0.005 * i;
      }
    }
    return p;
  };
  std::vector<double> capture_s, camera_s;
  for (int f = 0; f < kFrames; ++f) {
    capture_s.push_back(f / kFps);
    camera_s.push_back(kOffsetS + (1 + kDriftPpm * 1e-6) * f / kFps);
  }
  const NpyArray<double> truth = points_at(capture_s);
  testing::SyntheticDetectionOptions d;
  d.noise_px = 0.1;
  const NpyArray<double> on_clock = testing::MakeSyntheticDetections(rig, truth, d);
  const NpyArray<double> late = testing::MakeSyntheticDetections(rig, points_at(camera_s), d);
  NpyArray<float> k;
  k.shape = on_clock.shape;
  k.data.assign(on_clock.data.begin(), on_clock.data.end());
  for (int64_t f = 0; f < kFrames; ++f)
    for (int64_t v = 4; v < 8; ++v)
      for (int64_t p = 0; p < 21; ++p)
        for (int64_t c = 0; c < 3; ++c)
          k.data[static_cast<size_t>(((f * 8 + v) * 21 + p) * 3 + c)] =
              static_cast<float>(late.at(f, v, p, c));
  TempDir dir;
  const std::string capture = dir / "capture";
  ASSERT_TRUE(MakeDirectories(capture).ok());
  ASSERT_TRUE(calibration::SaveCalibration(capture + "/rig.json", rig).ok());
  ASSERT_TRUE(WriteNpy(capture + "/keypoints2d.npy", k).ok());
  CaptureManifest m;
  m.name = "synced_by_sound";
  m.fps = kFps;
  m.frame_first = 1;
  m.frame_count = kFrames;
  m.calibration = "rig.json";
  m.keypoints2d = "keypoints2d.npy";
  m.layout = "hand_21";
  for (const Camera& cam : rig.cameras) m.cameras.push_back({cam.name, cam.serial, "", {}});
  // The worst error (mm) of frames 2.. (frame 1 is before the late cameras started).
  const auto worst_mm = [&](const CaptureManifest& manifest, const std::string& name) {
    EXPECT_TRUE(WriteCaptureManifest(capture, manifest).ok());
    TriangulateStageOptions o;
    o.capture_dir = capture;
    o.result_dir = dir / name;
    o.triangulation.num_threads = 2;
    const auto s = RunTriangulateStage(o);
    EXPECT_TRUE(s.ok()) << s.status().message();
    auto points = ResultFolder(o.result_dir).ReadPoints3d(kTriangulationStage);
    EXPECT_TRUE(points.ok());
    double worst = 0;
    for (int64_t f = 1; f < kFrames; ++f)
      for (int64_t p = 0; p < 21; ++p)
        for (int64_t c = 0; c < 3; ++c)
          worst = std::max(worst, std::abs(points->at(f, p, c) - truth.at(f, p, c)));
    return 1000 * worst;
  };
  const double unsynced_mm = worst_mm(m, "unsynced");
  for (int v = 4; v < 8; ++v) {
    m.cameras[static_cast<size_t>(v)].offset_s = kOffsetS;
    m.cameras[static_cast<size_t>(v)].drift_ppm = kDriftPpm;
  }
  const double synced_mm = worst_mm(m, "synced");
  EXPECT_GT(unsynced_mm, 4.0) << "views 16 ms apart disagree";
  EXPECT_LT(synced_mm, 1.0) << "unsynced " << unsynced_mm << " mm";
  std::printf("worst error: %.3f mm without the camera clocks, %.3f mm with them\n",
              unsynced_mm,
              synced_mm);
}

}  // namespace
}  // namespace arco::pipeline
