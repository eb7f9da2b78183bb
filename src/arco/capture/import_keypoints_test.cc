// `arco capture import-keypoints`: hand-written MMPose and OpenPose output into a capture
// made by CreateCapture from generated videos.
#include "arco/capture/import_keypoints.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "arco/calibration/calibration_file.h"
#include "arco/capture/capture_new.h"
#include "arco/media/test_video.h"
#include "arco/mocap/capture.h"
#include "arco/pipeline/result_folder.h"
#include "arco/pipeline/triangulate_stage.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/testing/synthetic_views.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"
#include "arco/util/npy.h"

namespace arco::capture {
namespace {

namespace fs = std::filesystem;
using arco::testing::TempDir;

// Two cameras, 4 recorded frames; cam1 dropped global frame 2, so its video has 3.
std::string MakeCapture(const TempDir& dir, const std::string& instrument = "none") {
  Rig rig;
  for (const char* name : {"cam0", "cam1"}) {
    Camera c;
    c.name = name;
    c.width = 128;
    c.height = 96;
    c.fx = c.fy = 100;
    rig.cameras.push_back(c);
  }
  EXPECT_TRUE(calibration::SaveCalibration(dir / "rig.json", rig).ok());
  CaptureNewOptions o;
  o.calibration = dir / "rig.json";
  for (int v = 0; v < 2; ++v) {
    media::testing::IndexVideo video;
    video.frames = v == 0 ? 4 : 3;
    const std::string path = dir / ("v" + std::to_string(v) + ".mkv");
    EXPECT_TRUE(media::testing::WriteIndexVideo(path, video).ok());
    o.inputs.push_back({"cam" + std::to_string(v), path, false});
  }
  o.dropped_frames = {{"cam1", {2}}};
  o.instrument = instrument;
  o.output_dir = dir / "capture";
  const auto r = CreateCapture(o);
  EXPECT_TRUE(r.ok()) << r.status().message();
  return o.output_dir;
}

// An MMPose instance with every point at (x0 + p, y0) and score `score`, its box given.
std::string Instance(double x0, double y0, double score, double box_size) {
  std::string kp, sc;
  for (int p = 0; p < 133; ++p) {
    kp +=
        (p ? "," : "") + std::string("[") + std::to_string(x0 + p) + "," + std::to_string(y0) + "]";
    sc += (p ? "," : "") + std::to_string(score);
  }
  return "{\"keypoints\": [" + kp + "], \"keypoint_scores\": [" + sc + "], \"bbox\": [[0, 0, " +
         std::to_string(box_size) + ", " + std::to_string(box_size) + "]], \"bbox_score\": 0.9}";
}

void Write(const std::string& path, const std::string& text) {
  ASSERT_TRUE(AtomicWriteFile(path, text).ok()) << path;
}

TEST(ImportKeypoints, MmposePerVideoAndPerFrameFolder) {
  TempDir dir;
  const std::string capture = MakeCapture(dir);
  // cam0: MMPoseInferencer's per-video list (frame_id from 0); frame 2 has two people,
  // the second larger; frame 3 nobody.
  Write(dir / "cam0.json",
        "[{\"frame_id\": 0, \"instances\": [" + Instance(10, 20, 0.5, 50) + "]}," +
            "{\"frame_id\": 1, \"instances\": [" + Instance(11, 20, 0.5, 50) + "]}," +
            "{\"frame_id\": 2, \"instances\": [" + Instance(1, 1, 0.5, 10) + "," +
            Instance(12, 20, 1.7, 80) + "]}," + "{\"frame_id\": 3, \"instances\": []}]");
  // cam1: a folder of per-image files (natural order) of its 3 video frames.
  ASSERT_TRUE(MakeDirectories(dir / "cam1").ok());
  for (int k = 0; k < 3; ++k) {
    Write(dir / ("cam1/img" + std::to_string(k == 2 ? 10 : k + 1) + ".json"),
          "[" + Instance(100 + k, 30, 0.25, 40) + "]");
  }
  ImportKeypointsOptions o;
  o.capture_dir = capture;
  o.format = "mmpose";
  o.sources = {{"cam0", dir / "cam0.json"}, {"cam1", dir / "cam1"}};
  const auto r = ImportKeypoints(o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->layout, "coco_wholebody_133");
  EXPECT_EQ(r->report.people_kept, 6);  // 3 + 3 (cam0's frame 4 empty)
  EXPECT_EQ(r->report.frames_without_person, 1);
  EXPECT_EQ(r->report.frames_with_several, 1);
  EXPECT_EQ(r->report.scores_clamped, 133);

  const auto m = ReadCaptureManifest(capture);
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->layout, "coco_wholebody_133");
  ASSERT_TRUE(CheckCaptureKeypoints2d(capture, *m).ok());
  const auto header = ReadNpyHeader(dir / "capture/keypoints2d.npy");
  ASSERT_TRUE(header.ok());
  EXPECT_EQ(header->dtype, "float32");
  const auto k = ReadCaptureKeypoints2d(capture, *m);
  ASSERT_TRUE(k.ok()) << k.status().message();
  ASSERT_EQ(k->shape, (std::vector<int64_t>{4, 2, 133, 3}));
  // cam0, global frame 3 = video frame 2: the larger person, score clamped to 1.
  EXPECT_DOUBLE_EQ(k->at(2, 0, 5, 0), 17);
  EXPECT_DOUBLE_EQ(k->at(2, 0, 5, 1), 20);
  EXPECT_DOUBLE_EQ(k->at(2, 0, 5, 2), 1);
  EXPECT_TRUE(std::isnan(k->at(3, 0, 0, 0)));  // nobody
  // cam1: global 1 -> img1, global 2 dropped, global 3 -> img2, global 4 -> img10.
  EXPECT_DOUBLE_EQ(k->at(0, 1, 0, 0), 100);
  EXPECT_TRUE(std::isnan(k->at(1, 1, 0, 0)));
  EXPECT_DOUBLE_EQ(k->at(2, 1, 0, 0), 101);
  EXPECT_DOUBLE_EQ(k->at(3, 1, 0, 0), 102);
  EXPECT_FLOAT_EQ(static_cast<float>(k->at(3, 1, 0, 2)), 0.25f);

  // A second import needs overwrite.
  const auto again = ImportKeypoints(o);
  ASSERT_FALSE(again.ok());
  EXPECT_NE(again.status().message().find("already"), std::string::npos);
  o.overwrite = true;
  EXPECT_TRUE(ImportKeypoints(o).ok());
}

TEST(ImportKeypoints, OpenPoseFoldersIntoAnInstrumentLayout) {
  TempDir dir;
  const std::string capture = MakeCapture(dir, "cello");
  // BODY_25 with left shoulder (5) at (50, 60) and everything else undetected; the left
  // hand's wrist at (70, 80).
  std::string pose, hand;
  for (int i = 0; i < 25; ++i) pose += (i ? "," : "") + std::string(i == 5 ? "50,60,0.8" : "0,0,0");
  for (int i = 0; i < 21; ++i) hand += (i ? "," : "") + std::string(i == 0 ? "70,80,0.6" : "0,0,0");
  const std::string frame = "{\"version\": 1.3, \"people\": [{\"pose_keypoints_2d\": [" + pose +
                            "], \"hand_left_keypoints_2d\": [" + hand +
                            "], \"hand_right_keypoints_2d\": [], \"face_keypoints_2d\": []}]}";
  for (int v = 0; v < 2; ++v) {
    const std::string folder = dir / ("op" + std::to_string(v));
    ASSERT_TRUE(MakeDirectories(folder).ok());
    for (int f = 0; f < 4 - v; ++f) {
      Write(folder + "/video_" + std::to_string(f) + "_keypoints.json", frame);
    }
    Write(folder + "/notes.json", "not a frame");  // not *_keypoints.json: ignored
  }
  ImportKeypointsOptions o;
  o.capture_dir = capture;
  o.format = "openpose";
  o.sources = {{"cam1", dir / "op1"}, {"cam0", dir / "op0"}};
  const auto r = ImportKeypoints(o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->layout, "spd_cello");
  const auto m = ReadCaptureManifest(capture);
  ASSERT_TRUE(m.ok());
  const auto k = ReadCaptureKeypoints2d(capture, *m);
  ASSERT_TRUE(k.ok()) << k.status().message();
  const KeypointLayout* layout = FindKeypointLayout("spd_cello");
  ASSERT_EQ(k->shape, (std::vector<int64_t>{4, 2, layout->size(), 3}));
  const int shoulder = layout->Find("left_shoulder");
  const int wrist = layout->Find("left_hand_wrist");
  EXPECT_DOUBLE_EQ(k->at(0, 0, shoulder, 0), 50);
  EXPECT_DOUBLE_EQ(k->at(0, 0, shoulder, 1), 60);
  EXPECT_FLOAT_EQ(static_cast<float>(k->at(0, 0, shoulder, 2)), 0.8f);
  EXPECT_DOUBLE_EQ(k->at(3, 1, wrist, 0), 70);
  EXPECT_TRUE(std::isnan(k->at(0, 0, layout->Find("nose"), 0)));   // confidence 0
  EXPECT_TRUE(std::isnan(k->at(0, 0, layout->Find("nut_l"), 0)));  // instrument: none
  EXPECT_TRUE(std::isnan(k->at(1, 1, shoulder, 0)));               // dropped
}

TEST(RotateDecodedPixel, TurnsPixelCentresLikeTheFrame) {
  // A 4 x 2 frame turned clockwise is 2 x 4: its top-left pixel goes to the top right.
  const Eigen::Vector2i turned(2, 4);
  EXPECT_EQ(RotateDecodedPixel({0, 0}, 90, turned), Eigen::Vector2d(1, 0));
  EXPECT_EQ(RotateDecodedPixel({3, 0}, 90, turned), Eigen::Vector2d(1, 3));
  EXPECT_EQ(RotateDecodedPixel({3, 1}, 90, turned), Eigen::Vector2d(0, 3));
  EXPECT_EQ(RotateDecodedPixel({0, 0}, 270, turned), Eigen::Vector2d(0, 3));
  EXPECT_EQ(RotateDecodedPixel({1, 0}, 180, Eigen::Vector2i(4, 2)), Eigen::Vector2d(2, 1));
  EXPECT_EQ(RotateDecodedPixel({1.5, 0.25}, 0, Eigen::Vector2i(4, 2)), Eigen::Vector2d(1.5, 0.25));
  // 90 then 270 (in the turned frame) is where it started.
  const Eigen::Vector2d p(2.5, 1.25);
  EXPECT_TRUE(RotateDecodedPixel(RotateDecodedPixel(p, 90, {2, 4}), 270, {4, 2}).isApprox(p));
}

// A rotated camera: the pixels' frame must be said, and decoded pixels are turned.
TEST(ImportKeypoints, RotatedCameraNeedsPixelsAndTurnsDecodedOnes) {
  TempDir dir;
  const std::string capture = MakeCapture(dir);
  auto m = ReadCaptureManifest(capture);
  ASSERT_TRUE(m.ok());
  m->cameras[1].rotate_deg = 180;  // 128 x 96 either way
  ASSERT_TRUE(WriteCaptureManifest(capture, *m).ok());
  ASSERT_TRUE(MakeDirectories(dir / "frames").ok());
  for (int f = 0; f < 4; ++f) {
    Write(dir / ("frames/" + std::to_string(f) + ".json"), "[" + Instance(10, 20, 0.5, 5) + "]");
  }
  ImportKeypointsOptions o;
  o.capture_dir = capture;
  o.format = "mmpose";
  o.sources = {{"cam0", dir / "frames"}, {"cam1", dir / "frames"}};
  // cam1 has 3 video frames: a per-video file instead.
  Write(dir / "cam1.json",
        "[{\"frame_id\": 0, \"instances\": [" + Instance(10, 20, 0.5, 5) + "]}]");
  o.sources[1].path = dir / "cam1.json";
  const auto unsaid = ImportKeypoints(o);
  ASSERT_FALSE(unsaid.ok());
  EXPECT_NE(unsaid.status().message().find("rotate_deg 180"), std::string::npos)
      << unsaid.status().message();
  o.pixels = "calibration";
  ASSERT_TRUE(ImportKeypoints(o).ok());
  auto k = ReadCaptureKeypoints2d(capture, *ReadCaptureManifest(capture));
  ASSERT_TRUE(k.ok());
  EXPECT_DOUBLE_EQ(k->at(0, 1, 0, 0), 10);
  o.pixels = "decoded";
  o.overwrite = true;
  ASSERT_TRUE(ImportKeypoints(o).ok());
  k = ReadCaptureKeypoints2d(capture, *ReadCaptureManifest(capture));
  ASSERT_TRUE(k.ok());
  EXPECT_DOUBLE_EQ(k->at(0, 1, 0, 0), 127 - 10);  // turned by 180 in 128 x 96
  EXPECT_DOUBLE_EQ(k->at(0, 1, 0, 1), 95 - 20);
  EXPECT_DOUBLE_EQ(k->at(0, 0, 0, 0), 10);  // cam0 is not rotated
}

// The whole path from videos: capture new (one camera's video stored landscape and turned
// 90 degrees, one camera that dropped a frame) -> MMPose files of exact projections in
// the decoded frames -> import -> triangulate: every point back where it was.
TEST(ImportKeypoints, VideosToCaptureToTriangulation) {
  TempDir dir;
  testing::SyntheticRigOptions ro;
  ro.num_cameras = 4;
  ro.distortion = false;
  Rig rig = testing::MakeSyntheticRig(ro);
  for (Camera& c : rig.cameras) {  // 2300 x 2656 scaled to 128 x 160 (about 1/18)
    const double s = 128.0 / 2300.0;
    c.width = 128;
    c.height = 160;
    c.fx *= s;
    c.fy *= s;
    c.cx = c.cx * s;
    c.cy = c.cy * s;
  }
  ASSERT_TRUE(calibration::SaveCalibration(dir / "rig.json", rig).ok());
  constexpr int kFrames = 5;
  const NpyArray<double> truth = testing::MakeSyntheticPoints(kFrames, 133, 3);
  testing::SyntheticDetectionOptions d;
  d.noise_px = 0;
  const NpyArray<double> k = testing::MakeSyntheticDetections(rig, truth, d);

  CaptureNewOptions c;
  c.calibration = dir / "rig.json";
  c.output_dir = dir / "capture";
  c.rotate_deg = {{rig.cameras[1].name, 90}};
  c.dropped_frames = {{rig.cameras[2].name, {3}}};
  ImportKeypointsOptions o;
  o.capture_dir = c.output_dir;
  o.format = "mmpose";
  o.pixels = "decoded";
  for (int v = 0; v < 4; ++v) {
    const std::string name = rig.cameras[static_cast<size_t>(v)].name;
    media::testing::IndexVideo video;
    video.width = v == 1 ? 160 : 128;  // stored landscape, turned 90 degrees
    video.height = v == 1 ? 128 : 160;
    video.frames = v == 2 ? kFrames - 1 : kFrames;
    const std::string path = dir / (name + ".mkv");
    ASSERT_TRUE(media::testing::WriteIndexVideo(path, video).ok());
    c.inputs.push_back({name, path, false});
    // Detections in the decoded frames: the calibration's pixels turned back.
    std::string json = "[";
    int frame_id = 0;
    for (int f = 0; f < kFrames; ++f) {
      if (v == 2 && f == 2) continue;  // global frame 3 was dropped
      std::string kp, sc;
      for (int p = 0; p < 133; ++p) {
        Eigen::Vector2d px(k.at(f, v, p, 0), k.at(f, v, p, 1));
        if (v == 1) px = RotateDecodedPixel(px, 270, {160, 128});  // the decoded size
        char text[64];
        std::snprintf(text, sizeof text, "[%.9g, %.9g]", px.x(), px.y());
        kp += (p ? "," : "") + std::string(text);
        sc += (p ? "," : "") + std::to_string(k.at(f, v, p, 2));
      }
      json += std::string(frame_id > 0 ? "," : "") + "{\"frame_id\": " + std::to_string(frame_id) +
              ", \"instances\": [{\"keypoints\": [" + kp + "], \"keypoint_scores\": [" + sc +
              "]}]}";
      ++frame_id;
    }
    Write(dir / (name + ".json"), json + "]");
    o.sources.push_back({name, dir / (name + ".json")});
  }
  const auto created = CreateCapture(c);
  ASSERT_TRUE(created.ok()) << created.status().message();
  EXPECT_EQ(created->frames, kFrames);
  const auto imported = ImportKeypoints(o);
  ASSERT_TRUE(imported.ok()) << imported.status().message();
  pipeline::TriangulateStageOptions t;
  t.capture_dir = c.output_dir;
  t.result_dir = dir / "result";
  t.triangulation.point.max_reprojection_px = 1;  // exact data in 128 px images
  const auto triangulated = pipeline::RunTriangulateStage(t);
  ASSERT_TRUE(triangulated.ok()) << triangulated.status().message();
  const auto points = ReadNpy<double>(dir / "result/triangulation/points3d_raw.npy");
  ASSERT_TRUE(points.ok()) << points.status().message();
  ASSERT_EQ(points->shape, (std::vector<int64_t>{kFrames, 133, 3}));
  double worst_m = 0;
  for (int f = 0; f < kFrames; ++f) {
    for (int p = 0; p < 133; ++p) {
      for (int a = 0; a < 3; ++a) {
        worst_m = std::max(worst_m, std::abs(points->at(f, p, a) - truth.at(f, p, a)));
      }
    }
  }
  EXPECT_LT(worst_m, 1e-3) << "a point moved by " << worst_m << " m";
  // Every view agrees (the turned camera included); the dropped frame has one view fewer.
  const auto inliers = ReadNpy<int32_t>(dir / "result/triangulation/inlier_count.npy");
  ASSERT_TRUE(inliers.ok()) << inliers.status().message();
  for (int f = 0; f < kFrames; ++f) {
    for (int p = 0; p < 133; ++p) {
      ASSERT_EQ(inliers->at(f, p), f == 2 ? 3 : 4) << "frame " << f << " point " << p;
    }
  }
}

TEST(ImportKeypoints, BadInputsWriteNothing) {
  TempDir dir;
  const std::string capture = MakeCapture(dir);
  const std::string manifest_before = *ReadFileToString(capture + "/capture.json");
  ASSERT_TRUE(MakeDirectories(dir / "short").ok());
  for (int f = 0; f < 3; ++f) {
    Write(dir / ("short/f" + std::to_string(f) + ".json"), "[" + Instance(1, 1, 0.5, 5) + "]");
  }
  Write(dir / "broken.json", "[{\"keypoints\": [[1, 2]]}]");
  ImportKeypointsOptions o;
  o.capture_dir = capture;
  o.format = "mmpose";
  auto expect_bad = [&](const std::vector<ImportKeypointsSource>& sources,
                        const std::string& named) {
    o.sources = sources;
    const auto r = ImportKeypoints(o);
    ASSERT_FALSE(r.ok()) << named;
    EXPECT_EQ(r.status().message().rfind(named + ": ", 0), 0u) << r.status().message();
    EXPECT_EQ(*ReadFileToString(capture + "/capture.json"), manifest_before);
    EXPECT_FALSE(fs::exists(capture + "/keypoints2d.npy"));
    for (const auto& entry : fs::directory_iterator(capture)) {
      EXPECT_NE(entry.path().filename().string()[0], '.') << "temporary left: " << entry.path();
    }
  };
  const std::string manifest = JoinPath(capture, "capture.json");
  // cam0 has 4 video frames, the folder 3 files.
  expect_bad({{"cam0", dir / "short"}, {"cam1", dir / "short"}}, dir / "short");
  expect_bad({{"cam0", dir / "broken.json"}, {"cam1", dir / "short"}}, dir / "broken.json");
  expect_bad({{"cam1", dir / "short"}}, manifest);                           // cam0 missing
  expect_bad({{"cam9", dir / "short"}, {"cam1", dir / "short"}}, manifest);  // unknown
  expect_bad({{"cam0", dir / "none.json"}, {"cam1", dir / "short"}}, dir / "none.json");
}

TEST(ImportKeypointsOptions, ValidateNamesTheField) {
  ImportKeypointsOptions o;
  o.capture_dir = "c";
  o.format = "mmpose";
  o.sources = {{"cam0", "a.json"}};
  EXPECT_TRUE(o.Validate().ok());
  o.format = "yolo";
  EXPECT_NE(o.Validate().message().find("format"), std::string::npos);
  o.format = "openpose";
  o.sources.push_back({"cam0", "b.json"});
  EXPECT_NE(o.Validate().message().find("sources"), std::string::npos);
  o.sources.clear();
  EXPECT_NE(o.Validate().message().find("sources"), std::string::npos);
  o.sources = {{"cam0", "a.json"}};
  o.pixels = "sideways";
  EXPECT_NE(o.Validate().message().find("pixels"), std::string::npos);
}

}  // namespace
}  // namespace arco::capture
