// RefineCalibration (`arco calibrate refine`) on a synthetic capture (arco synth, the real
// 20-camera SPD rig, exact calibration truth) whose calibration was perturbed by 1-3
// degrees and 20-50 mm per camera (all but the reference camera, which holds the world
// frame): the refined rig against the truth, `arco run`'s accuracy against the unperturbed
// run, and bad input.
#include "arco/calibrate/calibration_refine.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "arco/calibrate/calibration_check.h"
#include "arco/calibration/calibration_file.h"
#include "arco/eval/evaluate.h"
#include "arco/geometry/rotation.h"
#include "arco/mocap/capture.h"
#include "arco/pipeline/run_capture.h"
#include "arco/pipeline/run_with_rig_test_support.h"
#include "arco/synth/capture_writer.h"
#include "arco/synth/synth.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"
#include "arco/util/npy.h"

namespace arco::calibrate {
namespace {

namespace fs = std::filesystem;
using arco::pipeline::testing::RunWithRig;
using arco::testing::TempDir;

// A 4-second cello scale (no audio rendering needed by refine; run's pitch stage reads it).
void WriteSyntheticCapture(const std::string& path) {
  auto calibration = calibration::LoadCalibration(std::string(ARCO_SHARED_DATA_DIR) +
                                                  "/spd/cello_1113_scale_camera.xml");
  ASSERT_TRUE(calibration.ok()) << calibration.status().message();
  synth::SynthOptions o;
  o.max_duration_s = 4.0;
  o.num_threads = 2;
  auto capture = synth::Generate(calibration->rig, o);
  ASSERT_TRUE(capture.ok()) << capture.status().message();
  synth::WriteOptions w;
  w.audio_render.tune_soundfont = false;
  const Status written = synth::WriteCapture(*capture, path, w);
  ASSERT_TRUE(written.ok()) << written.message();
}

// Every camera but the first turned by 1-3 degrees about a random axis through its centre
// and moved by 20-50 mm in a random direction (seeded).
Rig Perturb(const Rig& truth, uint32_t seed) {
  Rig rig = truth;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> angle_deg(1, 3), shift_mm(20, 50);
  std::normal_distribution<double> normal;
  for (size_t c = 1; c < rig.cameras.size(); ++c) {
    Camera& cam = rig.cameras[c];
    const Eigen::Vector3d axis =
        Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    const Eigen::Vector3d dir = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    const double a = angle_deg(rng) * M_PI / 180, s = shift_mm(rng);
    const Eigen::Vector3d centre = cam.CenterInWorld() + s * dir;
    cam.cam_from_world.rotation = RotationFromAxisAngle(a * axis) * cam.cam_from_world.rotation;
    cam.cam_from_world.translation = -cam.cam_from_world.rotation * centre;
  }
  return rig;
}

struct RigError {
  double worst_deg = 0, worst_mm = 0;
};

RigError Compare(const Rig& truth, const Rig& estimate) {
  RigError e;
  for (size_t c = 0; c < truth.cameras.size(); ++c) {
    e.worst_deg = std::max(e.worst_deg,
                           RotationAngleBetween(truth.cameras[c].cam_from_world.rotation,
                                                estimate.cameras[c].cam_from_world.rotation) *
                               180 / M_PI);
    e.worst_mm =
        std::max(e.worst_mm,
                 (truth.cameras[c].CenterInWorld() - estimate.cameras[c].CenterInWorld()).norm());
  }
  return e;
}

TEST(RefineCalibration, RecoversAPerturbedRigAndTheRunsAccuracy) {
  TempDir dir;
  const std::string capture = dir / "capture";
  WriteSyntheticCapture(capture);
  auto truth = calibration::LoadCalibration(capture + "/calibration.json");
  ASSERT_TRUE(truth.ok());
  const Rig perturbed = Perturb(truth->rig, 7);
  ASSERT_TRUE(calibration::SaveCalibration(dir / "perturbed.json", perturbed).ok());
  const RigError before = Compare(truth->rig, perturbed);

  CalibrationRefineOptions options;
  options.capture_dir = capture;
  options.calibration = dir / "perturbed.json";
  options.output = dir / "refined.json";
  auto refined = RefineCalibration(options);
  ASSERT_TRUE(refined.ok()) << refined.status().message();
  ASSERT_TRUE(FileExists(dir / "refined.json"));
  ASSERT_TRUE(FileExists(dir / "refined.report.json"));
  auto written = calibration::LoadCalibration(dir / "refined.json");
  ASSERT_TRUE(written.ok());
  const RigError after = Compare(truth->rig, written->rig);
  std::printf(
      "[ refine ] perturbed: worst %.2f deg %.1f mm; refined: worst %.4f deg %.3f mm; "
      "rms %.2f -> %.2f px; %lld points, string %.2f -> %.2f mm; passes %.2f %.2f %.2f s, %d %d %d "
      "iterations\n",
      before.worst_deg,
      before.worst_mm,
      after.worst_deg,
      after.worst_mm,
      refined->rms_before_px,
      refined->rms_after_px,
      static_cast<long long>(refined->points),
      refined->string_length_before_mm,
      refined->string_length_mm,
      refined->passes[0].time_s,
      refined->passes[1].time_s,
      refined->passes[2].time_s,
      refined->passes[0].iterations,
      refined->passes[1].iterations,
      refined->passes[2].iterations);
  EXPECT_GE(before.worst_deg, 1.0);
  EXPECT_LE(after.worst_deg, 0.1);
  EXPECT_LE(after.worst_mm, 2.0);
  ASSERT_EQ(refined->cameras.size(), 20u);
  EXPECT_TRUE(refined->cameras[0].reference);
  EXPECT_EQ(refined->cameras[0].rotation_change_deg, 0.0);
  for (const CameraRefinement& c : refined->cameras) {
    EXPECT_LT(c.rms_after_px, c.rms_before_px) << c.name;
    EXPECT_LT(c.rms_after_px, 4.0) << c.name;  // 2 px detector noise
  }

  // Bit for bit again; the output is not replaced without overwrite.
  options.output = dir / "again.json";
  auto again = RefineCalibration(options);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(ReadFileToString(dir / "refined.json").value(),
            ReadFileToString(dir / "again.json").value());
  auto exists = RefineCalibration(options);
  ASSERT_FALSE(exists.ok());
  EXPECT_NE(exists.status().message().find("--overwrite"), std::string::npos);

  // `arco run` with each calibration, scored against the truth.
  fs::create_directories(dir / "truth_run");
  fs::create_directories(dir / "perturbed_run");
  fs::create_directories(dir / "refined_run");
  const eval::MethodMetrics m_truth = RunWithRig(capture, truth->rig, dir / "truth_run");
  const eval::MethodMetrics m_perturbed = RunWithRig(capture, perturbed, dir / "perturbed_run");
  const eval::MethodMetrics m_refined = RunWithRig(capture, written->rig, dir / "refined_run");
  std::printf(
      "[ refine ] arco run, body MPJPE / hand MPJPE / contact deviation (mm): truth "
      "%.2f / %.2f / %.2f, perturbed %.2f / %.2f / %.2f, refined %.2f / %.2f / %.2f\n",
      m_truth.mpjpe_body_mm,
      m_truth.mpjpe_hand_mm,
      m_truth.contact_deviation_mm,
      m_perturbed.mpjpe_body_mm,
      m_perturbed.mpjpe_hand_mm,
      m_perturbed.contact_deviation_mm,
      m_refined.mpjpe_body_mm,
      m_refined.mpjpe_hand_mm,
      m_refined.contact_deviation_mm);
  EXPECT_GT(m_perturbed.mpjpe_body_mm, 1.05 * m_truth.mpjpe_body_mm);
  EXPECT_LE(m_refined.mpjpe_body_mm, 1.05 * m_truth.mpjpe_body_mm);
  EXPECT_LE(m_refined.mpjpe_hand_mm, 1.05 * m_truth.mpjpe_hand_mm);
  EXPECT_LE(m_refined.contact_deviation_mm, 1.05 * m_truth.contact_deviation_mm);
}

// --refine-focal: the focal lengths of every camera but the reference also off by up to 1 %.
// Focal length and distance trade off over a performer a metre deep, so the focal lengths
// come back only part of the way (docs/calibration.md); the orientations fully.
TEST(RefineCalibration, RefinesFocalLengthsToo) {
  TempDir dir;
  const std::string capture = dir / "capture";
  WriteSyntheticCapture(capture);
  auto truth = calibration::LoadCalibration(capture + "/calibration.json");
  ASSERT_TRUE(truth.ok());
  Rig perturbed = Perturb(truth->rig, 11);
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> focal(0.5, 1.0);
  for (size_t c = 1; c < perturbed.cameras.size(); ++c) {
    const double f = 1 + (c % 2 ? 1 : -1) * 0.01 * focal(rng);
    perturbed.cameras[c].fx *= f;
    perturbed.cameras[c].fy *= f;
  }
  ASSERT_TRUE(calibration::SaveCalibration(dir / "perturbed.json", perturbed).ok());
  CalibrationRefineOptions options;
  options.capture_dir = capture;
  options.calibration = dir / "perturbed.json";
  options.output = dir / "refined.json";
  options.refine_focal = true;
  auto refined = RefineCalibration(options);
  ASSERT_TRUE(refined.ok()) << refined.status().message();
  double focal_before = 0, focal_after = 0;
  for (size_t c = 0; c < truth->rig.cameras.size(); ++c) {
    const double f = truth->rig.cameras[c].fx;
    focal_before = std::max(focal_before, std::abs(perturbed.cameras[c].fx / f - 1));
    focal_after = std::max(focal_after, std::abs(refined->rig.cameras[c].fx / f - 1));
  }
  const RigError after = Compare(truth->rig, refined->rig);
  std::printf(
      "[ refine ] --refine-focal: focal off by %.3f %% -> %.3f %%; worst %.4f deg %.2f mm\n",
      100 * focal_before,
      100 * focal_after,
      after.worst_deg,
      after.worst_mm);
  EXPECT_GE(focal_before, 0.005);
  EXPECT_LE(focal_after, 0.5 * focal_before);
  EXPECT_LE(after.worst_deg, 0.1);
  EXPECT_LE(after.worst_mm, 10.0);
}

TEST(RefineCalibration, BadInputIsOneErrorAndNothingWritten) {
  TempDir dir;
  const std::string capture = dir / "capture";
  WriteSyntheticCapture(capture);
  CalibrationRefineOptions options;
  options.capture_dir = capture;
  options.output = dir / "refined.json";
  // No detection is that confident: not enough keypoints.
  options.min_score = 1.0;
  auto none = RefineCalibration(options);
  ASSERT_FALSE(none.ok());
  std::printf("%s\n", none.status().message().c_str());
  EXPECT_NE(none.status().message().find("keypoints2d.npy: only "), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "refined.json"));
  EXPECT_FALSE(fs::exists(dir / "refined.report.json"));

  // One camera only: the capture cut down to its first view.
  auto manifest = ReadCaptureManifest(capture);
  ASSERT_TRUE(manifest.ok());
  auto k = ReadNpy<float>(capture + "/keypoints2d.npy");
  ASSERT_TRUE(k.ok());
  NpyArray<float> one;
  one.shape = {k->shape[0], 1, k->shape[2], k->shape[3]};
  const int64_t per_view = k->shape[2] * k->shape[3];
  for (int64_t f = 0; f < k->shape[0]; ++f)
    one.data.insert(one.data.end(),
                    k->data.begin() + f * k->shape[1] * per_view,
                    k->data.begin() + f * k->shape[1] * per_view + per_view);
  ASSERT_TRUE(WriteNpy(capture + "/keypoints2d.npy", one).ok());
  manifest->cameras.resize(1);
  ASSERT_TRUE(WriteCaptureManifest(capture, *manifest).ok());
  options.min_score = 0.6;
  auto single = RefineCalibration(options);
  ASSERT_FALSE(single.ok());
  std::printf("%s\n", single.status().message().c_str());
  EXPECT_NE(single.status().message().find("at least two cameras"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "refined.json"));
  EXPECT_FALSE(fs::exists(dir / "refined.report.json"));
}

}  // namespace
}  // namespace arco::calibrate
