#include "arco/calibrate/calibration_check.h"

#include <gtest/gtest.h>

#include "arco/calibration/calibration_file.h"
#include "arco/geometry/rotation.h"
#include "arco/mocap/capture.h"
#include "arco/pipeline/triangulate_stage.h"
#include "arco/testing/synthetic_views.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"
#include "arco/util/npy.h"

namespace arco::calibrate {
namespace {

using arco::testing::TempDir;
using pipeline::RunTriangulateStage;
using pipeline::TriangulateStageOptions;

// 8 cameras, 21 points in 40 frames, 1 px noise and 5 % outliers.
void WriteCapture(const std::string& dir, Rig* rig) {
  testing::SyntheticRigOptions ro;
  ro.num_cameras = 8;
  *rig = testing::MakeSyntheticRig(ro);
  const NpyArray<double> truth = testing::MakeSyntheticPoints(40, 21, 5);
  testing::SyntheticDetectionOptions d;
  d.outlier_fraction = 0.05;
  d.missing_fraction = 0.1;
  const NpyArray<double> k = testing::MakeSyntheticDetections(*rig, truth, d);
  ASSERT_TRUE(MakeDirectories(dir).ok());
  ASSERT_TRUE(calibration::SaveCalibration(dir + "/rig.json", *rig).ok());
  NpyArray<float> kf;
  kf.shape = k.shape;
  kf.data.assign(k.data.begin(), k.data.end());
  ASSERT_TRUE(WriteNpy(dir + "/keypoints2d.npy", kf).ok());
  CaptureManifest m;
  m.name = "synthetic";
  m.frame_first = 1;
  m.frame_count = 40;
  m.calibration = "rig.json";
  m.keypoints2d = "keypoints2d.npy";
  m.layout = "hand_21";
  for (const Camera& cam : rig->cameras) m.cameras.push_back({cam.name, cam.serial, "", {}});
  ASSERT_TRUE(WriteCaptureManifest(dir, m).ok());
}

TEST(CheckCalibration, FlagsOnlyACameraTurnedByOneDegree) {
  TempDir dir;
  Rig rig;
  WriteCapture(dir / "capture", &rig);
  CalibrationCheckOptions options;
  options.capture_dir = dir / "capture";
  auto good = CheckCalibration(options);
  ASSERT_TRUE(good.ok()) << good.status().message();
  EXPECT_TRUE(good->flagged.empty()) << good->ToJson().dump();
  EXPECT_EQ(good->frames, 40);
  ASSERT_EQ(good->cameras.size(), 8u);
  for (const CameraCheck& c : good->cameras) {
    EXPECT_GT(c.residuals, 300) << c.name;
    EXPECT_LT(c.median_px, 2.0) << c.name;  // 1 px noise per axis
  }

  // A copy of the calibration with camera 3 turned by 1 degree about its centre.
  Rig moved = rig;
  Camera& turned = moved.cameras[3];
  const Eigen::Vector3d centre = turned.CenterInWorld();
  turned.cam_from_world.rotation =
      RotationFromAxisAngle(Eigen::Vector3d(0, M_PI / 180, 0)) * turned.cam_from_world.rotation;
  turned.cam_from_world.translation = -turned.cam_from_world.rotation * centre;
  ASSERT_TRUE(calibration::SaveCalibration(dir / "moved.json", moved).ok());
  options.calibration = dir / "moved.json";
  auto bad = CheckCalibration(options);
  ASSERT_TRUE(bad.ok()) << bad.status().message();
  std::printf("check: rig median %.2f px; cam3 turned 1 deg: median %.1f px\n",
              bad->rig_median_px,
              bad->cameras[3].median_px);
  ASSERT_EQ(bad->flagged, std::vector<std::string>{rig.cameras[3].name});
  EXPECT_TRUE(bad->cameras[3].flagged);
  // Off in every frame: one range over the whole capture (frames 1..40).
  ASSERT_EQ(bad->cameras[3].off_frames.size(), 1u);
  EXPECT_EQ(bad->cameras[3].off_frames[0], (std::pair<int64_t, int64_t>{1, 40}));
  EXPECT_EQ(bad->ToJson()["flagged"][0], rig.cameras[3].name);
}

// A result folder (`arco triangulate` of the capture): its points against the capture's
// detections; the same copy with camera 3 turned by 1 degree is flagged.
TEST(CheckCalibration, ResultFolderUsesItsPointsAndItsCapture) {
  TempDir dir;
  Rig rig;
  WriteCapture(dir / "capture", &rig);
  TriangulateStageOptions t;
  t.capture_dir = dir / "capture";
  t.result_dir = dir / "result";
  auto triangulated = RunTriangulateStage(t);
  ASSERT_TRUE(triangulated.ok()) << triangulated.status().message();
  CalibrationCheckOptions options;
  options.capture_dir = dir / "result";
  auto good = CheckCalibration(options);
  ASSERT_TRUE(good.ok()) << good.status().message();
  EXPECT_EQ(good->result, dir / "result");
  EXPECT_EQ(good->ToJson()["result"], dir / "result");
  EXPECT_TRUE(good->flagged.empty()) << good->ToJson().dump();
  EXPECT_EQ(good->frames, 40);
  for (const CameraCheck& c : good->cameras) {
    EXPECT_GT(c.residuals, 300) << c.name;
    EXPECT_LT(c.median_px, 2.0) << c.name;
  }
  Rig moved = rig;
  Camera& turned = moved.cameras[3];
  const Eigen::Vector3d centre = turned.CenterInWorld();
  turned.cam_from_world.rotation =
      RotationFromAxisAngle(Eigen::Vector3d(0, M_PI / 180, 0)) * turned.cam_from_world.rotation;
  turned.cam_from_world.translation = -turned.cam_from_world.rotation * centre;
  ASSERT_TRUE(calibration::SaveCalibration(dir / "moved.json", moved).ok());
  options.calibration = dir / "moved.json";
  auto bad = CheckCalibration(options);
  ASSERT_TRUE(bad.ok()) << bad.status().message();
  std::printf("check result: rig median %.2f px; cam3 turned 1 deg: median %.1f px\n",
              bad->rig_median_px,
              bad->cameras[3].median_px);
  ASSERT_EQ(bad->flagged, std::vector<std::string>{rig.cameras[3].name});
  ASSERT_EQ(bad->cameras[3].off_frames.size(), 1u);
  EXPECT_EQ(bad->cameras[3].off_frames[0], (std::pair<int64_t, int64_t>{1, 40}));
}

// The real SPD rig: the four labelled views of frame 128 with the session's Metashape
// calibration, and a copy with one of the four cameras turned by 1 degree.
TEST(CheckCalibration, RealSpdLabelledViews) {
  TempDir dir;
  const std::string spd = std::string(ARCO_SHARED_DATA_DIR) + "/spd/";
  const std::string calibration = spd + "cello_1113_scale_camera.xml";
  CalibrationCheckOptions options;
  options.calibration = calibration;
  const char* serials[] = {"21334181", "21334190", "21334211", "21334237"};
  for (const char* s : serials)
    options.label_views.emplace_back(s,
                                     spd + "labels_frame128/cello_1113_scale_" + s + "_128.json");
  auto good = CheckCalibration(options);
  ASSERT_TRUE(good.ok()) << good.status().message();
  EXPECT_TRUE(good->flagged.empty()) << good->ToJson().dump();
  for (const CameraCheck& c : good->cameras) EXPECT_GE(c.residuals, 5) << c.name;

  auto loaded = calibration::LoadCalibration(calibration);
  ASSERT_TRUE(loaded.ok());
  Rig moved = loaded->rig;
  Camera& turned = moved.cameras[moved.FindCamera("21334211")];
  const Eigen::Vector3d centre = turned.CenterInWorld();
  turned.cam_from_world.rotation =
      RotationFromAxisAngle(Eigen::Vector3d(M_PI / 180, 0, 0)) * turned.cam_from_world.rotation;
  turned.cam_from_world.translation = -turned.cam_from_world.rotation * centre;
  ASSERT_TRUE(calibration::SaveCalibration(dir / "moved.json", moved).ok());
  options.calibration = dir / "moved.json";
  auto bad = CheckCalibration(options);
  ASSERT_TRUE(bad.ok()) << bad.status().message();
  std::printf("SPD frame 128: medians %.2f %.2f %.2f %.2f px; 21334211 turned 1 deg: %.1f px\n",
              good->cameras[0].median_px,
              good->cameras[1].median_px,
              good->cameras[2].median_px,
              good->cameras[3].median_px,
              bad->cameras[2].median_px);
  EXPECT_EQ(bad->flagged, std::vector<std::string>{"21334211"});
}

TEST(CheckCalibration, ErrorsNameTheFile) {
  TempDir dir;
  Rig rig;
  WriteCapture(dir / "capture", &rig);
  CalibrationCheckOptions options;
  options.capture_dir = dir / "capture";
  options.calibration = dir / "missing.json";
  auto missing = CheckCalibration(options);
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().message().rfind(dir / "missing.json", 0), 0u)
      << missing.status().message();
  options.calibration.clear();
  options.min_views = 9;  // more than the 8 cameras
  auto none = CheckCalibration(options);
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.status().message().find("nothing to check"), std::string::npos);
  options.min_views = 3;
  options.flag_ratio = 0.5;
  EXPECT_NE(options.Validate().message().find("flag_ratio"), std::string::npos);
}

}  // namespace
}  // namespace arco::calibrate
