#include "arco/capture/import_spd.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "arco/calibration/calibration_file.h"
#include "arco/capture/label_views.h"
#include "arco/pipeline/result_folder.h"
#include "arco/pipeline/triangulate_stage.h"
#include "arco/testing/synthetic_views.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"

namespace arco::capture {
namespace {

using arco::testing::TempDir;

const std::string kCalibration =
    std::string(ARCO_SHARED_DATA_DIR) + "/spd/cello_1113_scale_camera.xml";

// Synthetic 3D points seen by the real SPD rig, written as SPD folders with a summary
// that drops one frame of one camera; imported, then triangulated end to end.
TEST(ImportSpdCapture, SpdFoldersToCaptureToTriangulation) {
  TempDir dir;
  auto calibration = calibration::LoadCalibration(kCalibration);
  ASSERT_TRUE(calibration.ok()) << calibration.status().message();
  Rig rig = calibration->rig;
  rig.cameras.resize(6);
  // Points near the cello of frame 128 (metashape units, about 2 m per unit).
  NpyArray<double> truth = testing::MakeSyntheticPoints(3, 142, 9);
  for (int64_t i = 0; i < 3 * 142; ++i) {
    truth.data[3 * i + 0] = 0.1 + 0.25 * (truth.data[3 * i + 0]);
    truth.data[3 * i + 1] = 0.0 + 0.25 * (truth.data[3 * i + 1]);
    truth.data[3 * i + 2] = -1.1 + 0.2 * (truth.data[3 * i + 2] - 1.0);
  }
  testing::SyntheticDetectionOptions d;
  d.noise_px = 0.5;
  NpyArray<double> k = testing::MakeSyntheticDetections(rig, truth, d);
  SpdImportOptions spd;
  spd.human_dir = dir / "human";
  spd.instrument_dir = dir / "cello";
  for (const Camera& c : rig.cameras) spd.serials.push_back(c.serial);
  spd.frame_first = 10;
  spd.frame_last = 12;
  spd.frame_drops = {{spd.serials[2], {11}}};
  for (int p = 0; p < 142; ++p) {
    for (int c = 0; c < 3; ++c) k.at(1, 2, p, c) = NAN;
  }
  ASSERT_TRUE(ExportSpdKeypoints(spd, k).ok());

  // A keypoint folder of a camera the calibration lacks; the log's drops after the last
  // frame name no frame of the capture.
  ASSERT_TRUE(MakeDirectories(dir / "human/99999999").ok());
  ASSERT_TRUE(AtomicWriteFile(dir / "summary.json",
                              "{\"StartFrame\": 10, \"EndFrame\": 12, \"FrameDropIDLog\": {\"" +
                                  spd.serials[2] + "\": [11, 11, 400]}}")
                  .ok());

  ImportSpdOptions o;
  o.calibration = kCalibration;
  o.summary = dir / "summary.json";
  o.human_dir = dir / "human";
  o.instrument_dir = dir / "cello";
  o.output_dir = dir / "capture";
  auto imported = ImportSpdCapture(o);
  ASSERT_TRUE(imported.ok()) << imported.status().message();
  EXPECT_EQ(imported->frames, 3);
  EXPECT_EQ(imported->views, 6);  // the cameras with a folder, in calibration order
  EXPECT_EQ(imported->points, 142);
  EXPECT_EQ(imported->files.frames_dropped, 1);
  ASSERT_EQ(imported->warnings.size(), 1u);
  EXPECT_EQ(imported->warnings[0],
            (dir / "human/99999999") + ": camera 99999999 is not in " + kCalibration +
                "; its keypoints are not imported");
  auto manifest = ReadCaptureManifest(o.output_dir);
  ASSERT_TRUE(manifest.ok()) << manifest.status().message();
  EXPECT_EQ(manifest->layout, "spd_cello");
  EXPECT_EQ(manifest->frame_first, 10);
  EXPECT_EQ(manifest->cameras[2].dropped_frames, (std::vector<int64_t>{11}));
  EXPECT_EQ(manifest->VideoFrameNumber(2, 12), 11);

  pipeline::TriangulateStageOptions t;
  t.capture_dir = o.output_dir;
  t.result_dir = dir / "result";
  auto run = pipeline::RunTriangulateStage(t);
  ASSERT_TRUE(run.ok()) << run.status().message();
  EXPECT_EQ(run->triangulation.triangulated, 3 * 142);
  auto points = pipeline::ResultFolder(t.result_dir).ReadPoints3d(pipeline::kTriangulationStage);
  ASSERT_TRUE(points.ok());
  double worst = 0;
  for (size_t i = 0; i < points->data.size(); ++i) {
    worst = std::max(worst, std::abs(points->data[i] - truth.data[i]));
  }
  EXPECT_LT(worst, 2e-3);  // metashape units: about 4 mm
  EXPECT_LT(run->triangulation.median_rms_reprojection_px, 1.0);

  // The output folder must not be reused; bad inputs leave nothing behind.
  auto again = ImportSpdCapture(o);
  ASSERT_FALSE(again.ok());
  EXPECT_NE(again.status().message().find("capture exists and is not empty (--overwrite"),
            std::string::npos);
  o.output_dir = dir / "capture2";
  o.serials = {"12345"};
  auto bad = ImportSpdCapture(o);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("\"12345\" is not in"), std::string::npos);
  o.serials.clear();
  o.summary.clear();
  bad = ImportSpdCapture(o);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("frame range"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(o.output_dir));
}

}  // namespace
}  // namespace arco::capture
