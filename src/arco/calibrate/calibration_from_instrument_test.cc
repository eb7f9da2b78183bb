// CalibrateFromInstrument (`arco calibrate from-instrument`) on a synthetic two-camera
// capture (arco synth: two cameras of the real SPD rig, distortion removed as a phone's
// video has it; the instrument's 2D points with detector-like noise): the estimated rig
// against the exact truth with the true focal length and one 10 % off, `arco run` with
// it, and bad input.
#include "arco/calibrate/calibration_from_instrument.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "arco/calibration/calibration_file.h"
#include "arco/eval/evaluate.h"
#include "arco/geometry/rotation.h"
#include "arco/media/test_video.h"
#include "arco/mocap/capture.h"
#include "arco/pipeline/run_capture.h"
#include "arco/pipeline/run_with_rig_test_support.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/synth/capture_writer.h"
#include "arco/synth/synth.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"
#include "arco/util/json_io.h"
#include "arco/util/npy.h"

namespace arco::calibrate {
namespace {

namespace fs = std::filesystem;
using arco::pipeline::testing::RunWithRig;
using arco::testing::TempDir;

constexpr int kImageWidth = 2300, kImageHeight = 2656;  // the SPD cameras'

// A 4-second cello scale seen by two of the SPD rig's cameras, about 1.8 m apart.
void WriteTwoCameraCapture(const std::string& path) {
  auto calibration = calibration::LoadCalibration(std::string(ARCO_SHARED_DATA_DIR) +
                                                  "/spd/cello_1113_scale_camera.xml");
  ASSERT_TRUE(calibration.ok()) << calibration.status().message();
  Rig rig;
  rig.units = calibration->rig.units;
  for (int c : {0, 18}) {
    Camera cam = calibration->rig.cameras[c];
    cam.distortion = Distortion();
    rig.cameras.push_back(cam);
  }
  synth::SynthOptions o;
  o.max_duration_s = 4.0;
  o.num_threads = 2;
  auto capture = synth::Generate(rig, o);
  ASSERT_TRUE(capture.ok()) << capture.status().message();
  synth::WriteOptions w;
  w.audio_render.tune_soundfont = false;
  const Status written = synth::WriteCapture(*capture, path, w);
  ASSERT_TRUE(written.ok()) << written.message();
}

// Camera 1 against camera 0 (the estimate's world): the gauge-free part of a two-camera rig.
struct RelativeError {
  double rotation_deg = 0, position_mm = 0, baseline_rel = 0;
};

RelativeError CompareRelative(const Rig& truth, const Rig& estimate) {
  auto relative = [](const Rig& rig, Eigen::Matrix3d* R, Eigen::Vector3d* centre) {
    const Camera &a = rig.cameras[0], &b = rig.cameras[1];
    *R = b.cam_from_world.rotation * a.cam_from_world.rotation.transpose();
    *centre = a.PointInCamera(b.CenterInWorld());  // camera 1's centre in camera 0's frame
  };
  Eigen::Matrix3d Rt, Re;
  Eigen::Vector3d ct, ce;
  relative(truth, &Rt, &ct);
  relative(estimate, &Re, &ce);
  RelativeError e;
  e.rotation_deg = RotationAngleBetween(Rt, Re) * 180 / M_PI;
  e.position_mm = (ct - ce).norm();
  e.baseline_rel = ce.norm() / ct.norm() - 1;
  return e;
}

CalibrationFromInstrumentOptions Options(const std::string& capture, const std::string& output) {
  CalibrationFromInstrumentOptions o;
  o.capture_dir = capture;
  o.output = output;
  o.image_width = kImageWidth;
  o.image_height = kImageHeight;
  return o;
}

TEST(CalibrateFromInstrument, RecoversTwoCamerasWithTheTrueAndAWrongFocal) {
  TempDir dir;
  const std::string capture = dir / "capture";
  WriteTwoCameraCapture(capture);
  auto truth = calibration::LoadCalibration(capture + "/calibration.json");
  ASSERT_TRUE(truth.ok());
  const double true_focal = truth->rig.cameras[0].fx;
  Rig wrong_focal_rig;
  // The true focal length held (--fix-focal), then the true one and one 10 % long refined.
  for (const auto& [scale, refine_focal] : {std::pair{1.0, false}, {1.0, true}, {1.1, true}}) {
    const std::string output = dir / ("focal" + std::to_string(int(scale * 100)) +
                                      (refine_focal ? "" : "_fixed") + ".json");
    CalibrationFromInstrumentOptions options = Options(capture, output);
    options.focal_px = scale * true_focal;
    options.refine_focal = refine_focal;
    auto result = CalibrateFromInstrument(options);
    ASSERT_TRUE(result.ok()) << result.status().message();
    ASSERT_TRUE(FileExists(output));
    ASSERT_TRUE(FileExists(RefineReportPath(output)));
    auto written = calibration::LoadCalibration(output);
    ASSERT_TRUE(written.ok());
    EXPECT_EQ(written->rig.units, "mm");
    ASSERT_EQ(written->rig.cameras.size(), 2u);
    const RelativeError e = CompareRelative(truth->rig, written->rig);
    const double focal_error = written->rig.cameras[1].fx / true_focal - 1;
    std::printf(
        "[ from-instrument ] focal x%.2f%s: PnP in %d/%d frames (rms %.2f/%.2f px), %d shared; "
        "relative pose error %.3f deg, %.2f mm (baseline %+.3f %%); focal %+.2f %%; string "
        "%.1f mm initial vs %.1f mm, triangulated %.1f +- %.1f mm (%d frames); reprojection "
        "%.2f -> %.2f px\n",
        scale,
        refine_focal ? " refined" : " held",
        result->cameras[0].pnp_frames,
        result->cameras[1].pnp_frames,
        result->cameras[0].pnp_rms_px,
        result->cameras[1].pnp_rms_px,
        result->shared_frames,
        e.rotation_deg,
        e.position_mm,
        100 * e.baseline_rel,
        100 * focal_error,
        result->string_length_initial_mm,
        result->string_length_mm,
        result->string_length_measured_mm,
        result->string_length_spread_mm,
        result->string_length_frames,
        result->rms_initial_px,
        result->rms_px);
    if (!refine_focal) {
      // Measured: the true focal length held, 0.4 deg and 15 mm (seeds 0-3 of the CLI:
      // 0.39-0.44 deg, 14.9-15.9 mm).
      EXPECT_LE(e.rotation_deg, 1.0);
      EXPECT_LE(e.position_mm, 20.0);
      EXPECT_LE(std::abs(e.baseline_rel), 0.005);
    } else {
      // Measured on this take (seed 0): 0.37 deg, 26 mm, baseline -0.45 %, focal +0.15 %
      // from either focal length (the same minimum). NOT a property of the method: on
      // seeds 1-3 the refined focal lengths end 0.7-11 % off and the pair 0.8-5.5 deg,
      // 59-466 mm (docs/calibration.md): two views hardly fix a focal length. This
      // checks that the refinement does not get worse on this take.
      EXPECT_LE(e.rotation_deg, 1.0);
      EXPECT_LE(e.position_mm, 50.0);
      EXPECT_LE(std::abs(e.baseline_rel), 0.015);
      EXPECT_LE(std::abs(focal_error), 0.02);
    }
    EXPECT_LE(result->rms_px, 4.0);  // 2 px detector noise
    // Measured: 694.9 +- 1.3 mm over 92 frames (the model's 695).
    EXPECT_NEAR(result->string_length_measured_mm, result->string_length_mm, 3.0);
    EXPECT_GE(result->string_length_frames, 50);
    if (scale != 1.0) wrong_focal_rig = written->rig;
  }

  // `arco run` with the estimated calibration (the one from the wrong focal length) against
  // the run with the truth. The estimate's world is its first camera's; the truth's is
  // SPD's: the estimate is put in the truth's world through the first camera (the gauge no
  // image measures), so that eval compares like with like.
  const Eigen::Matrix3d R0 = truth->rig.cameras[0].cam_from_world.rotation;
  const Eigen::Vector3d t0 = truth->rig.cameras[0].cam_from_world.translation;
  for (Camera& cam : wrong_focal_rig.cameras) {
    cam.cam_from_world.translation += cam.cam_from_world.rotation * t0;
    cam.cam_from_world.rotation = cam.cam_from_world.rotation * R0;
  }
  fs::create_directories(dir / "truth_run");
  fs::create_directories(dir / "estimate_run");
  const eval::MethodMetrics m_truth = RunWithRig(capture, truth->rig, dir / "truth_run");
  const eval::MethodMetrics m_estimate = RunWithRig(capture, wrong_focal_rig, dir / "estimate_run");
  std::printf(
      "[ from-instrument ] arco run, body MPJPE / hand MPJPE / contact deviation (mm): truth "
      "%.2f / %.2f / %.2f, estimated %.2f / %.2f / %.2f\n",
      m_truth.mpjpe_body_mm,
      m_truth.mpjpe_hand_mm,
      m_truth.contact_deviation_mm,
      m_estimate.mpjpe_body_mm,
      m_estimate.mpjpe_hand_mm,
      m_estimate.contact_deviation_mm);
  // Measured: body 28.8 mm (truth's run 9.0), hand 7.1 mm (7.3), contact 27.6 mm (2.7).
  // Body and contact are world positions: they carry the first camera's gauge, i.e. the
  // whole scene turned by the relative rotation's error (0.37 deg at 2-3 m) and scaled by
  // the baseline's (0.45 %); the hand's error, wrist-relative, is as good as with the truth.
  EXPECT_LE(m_estimate.mpjpe_body_mm, 45.0);
  EXPECT_LE(m_estimate.mpjpe_hand_mm, 1.1 * m_truth.mpjpe_hand_mm);
}

// Without --image-size the size comes from each camera's video, turned by its rotate_deg
// (a portrait phone video: coded 2656 x 2304, turned 90 degrees to 2304 x 2656).
TEST(CalibrateFromInstrument, ReadsTheImageSizeFromTheVideos) {
  TempDir dir;
  const std::string capture = dir / "capture";
  WriteTwoCameraCapture(capture);
  media::testing::IndexVideo video;
  video.width = 2656;
  video.height = 2304;
  video.frames = 2;
  ASSERT_TRUE(media::testing::WriteIndexVideo(capture + "/cam.mkv", video).ok());
  auto manifest = ReadCaptureManifest(capture);
  ASSERT_TRUE(manifest.ok());
  for (CaptureCamera& cam : manifest->cameras) cam.video = "cam.mkv", cam.rotate_deg = 90;
  ASSERT_TRUE(WriteCaptureManifest(capture, *manifest).ok());
  CalibrationFromInstrumentOptions options = Options(capture, dir / "rig.json");
  options.image_width = options.image_height = 0;
  options.fov_deg = 60;
  auto result = CalibrateFromInstrument(options);
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_EQ(result->focal_source, "--fov-deg 60");
  for (const FromInstrumentCamera& c : result->cameras) {
    EXPECT_EQ(c.width, 2304);
    EXPECT_EQ(c.height, 2656);
    EXPECT_EQ(c.size_source, "video");
    EXPECT_NEAR(c.initial_focal_px, 0.5 * 2656 / std::tan(M_PI / 6), 1e-9);
  }
  EXPECT_NEAR(result->rig.cameras[1].cx, 0.5 * 2303, 1e-9);
}

TEST(CalibrateFromInstrument, BadInputIsOneErrorAndNothingWritten) {
  TempDir dir;
  const std::string capture = dir / "capture";
  WriteTwoCameraCapture(capture);
  const std::string output = dir / "rig.json";
  auto nothing_written = [&] {
    EXPECT_FALSE(fs::exists(output));
    EXPECT_FALSE(fs::exists(dir / "rig.report.json"));
  };
  // No instrument detection is that confident: the first camera never sees it.
  CalibrationFromInstrumentOptions options = Options(capture, output);
  options.min_score = 1.0;
  auto none = CalibrateFromInstrument(options);
  ASSERT_FALSE(none.ok());
  std::printf("%s\n", none.status().message().c_str());
  EXPECT_NE(none.status().message().find("keypoints2d.npy: camera "), std::string::npos);
  EXPECT_NE(none.status().message().find(" never shows 5 "), std::string::npos);
  nothing_written();

  // No image size: the synthetic capture has no videos.
  options = Options(capture, output);
  options.image_width = options.image_height = 0;
  auto size = CalibrateFromInstrument(options);
  ASSERT_FALSE(size.ok());
  EXPECT_NE(size.status().message().find("--image-size"), std::string::npos);
  nothing_written();

  // Invalid options name the field.
  options = Options(capture, output);
  options.min_points = 3;
  auto points = CalibrateFromInstrument(options);
  ASSERT_FALSE(points.ok());
  EXPECT_NE(points.status().message().find("min_points"), std::string::npos);
  options = Options(capture, output);
  options.focal_px = 1000;
  options.fov_deg = 60;
  EXPECT_FALSE(options.Validate().ok());
  nothing_written();
}

// One phone: the camera's frame is the world, its intrinsics as given, and the report says
// how well the instrument's model fits its points; nothing is refined or measured.
TEST(CalibrateFromInstrument, OneCameraIsItsOwnWorld) {
  TempDir dir;
  const std::string capture = dir / "capture";
  WriteTwoCameraCapture(capture);
  auto truth = calibration::LoadCalibration(capture + "/calibration.json");
  ASSERT_TRUE(truth.ok());
  // The first camera alone: its column of keypoints2d and its entry of capture.json.
  auto manifest = ReadCaptureManifest(capture);
  ASSERT_TRUE(manifest.ok());
  auto keypoints = ReadCaptureKeypoints2d(capture, *manifest);
  ASSERT_TRUE(keypoints.ok());
  NpyArray<double> first;
  const int64_t frames = keypoints->shape[0], points = keypoints->shape[2];
  first.shape = {frames, 1, points, 3};
  for (int64_t f = 0; f < frames; ++f)
    for (int64_t p = 0; p < points; ++p)
      for (int64_t k = 0; k < 3; ++k) first.data.push_back(keypoints->at(f, 0, p, k));
  ASSERT_TRUE(WriteNpy(ResolveCapturePath(capture, manifest->keypoints2d), first).ok());
  manifest->cameras.resize(1);
  ASSERT_TRUE(WriteCaptureManifest(capture, *manifest).ok());

  const std::string output = dir / "one.json";
  CalibrationFromInstrumentOptions options = Options(capture, output);
  options.focal_px = truth->rig.cameras[0].fx;
  auto result = CalibrateFromInstrument(options);
  ASSERT_TRUE(result.ok()) << result.status().message();
  auto written = calibration::LoadCalibration(output);
  ASSERT_TRUE(written.ok());
  ASSERT_TRUE(FileExists(RefineReportPath(output)));
  ASSERT_EQ(written->rig.cameras.size(), 1u);
  const Camera& cam = written->rig.cameras[0];
  EXPECT_EQ(written->rig.units, "mm");
  EXPECT_EQ(cam.fx, truth->rig.cameras[0].fx);
  EXPECT_EQ(cam.width, kImageWidth);
  EXPECT_TRUE(cam.cam_from_world.rotation.isIdentity(0));
  EXPECT_TRUE(cam.cam_from_world.translation.isZero(0));
  std::printf("[ from-instrument ] one camera: PnP in %d of %lld frames, rms %.2f px\n",
              result->cameras[0].pnp_frames,
              static_cast<long long>(frames),
              result->rms_px);
  // The synthetic detector's instrument points against the nominal cello's shape.
  EXPECT_GT(result->cameras[0].pnp_frames, frames / 2);
  EXPECT_LT(result->rms_px, 10);
  EXPECT_FALSE(std::isfinite(result->string_length_measured_mm));
  ASSERT_FALSE(result->warnings.empty());
  EXPECT_NE(result->warnings[0].find("one camera: its frame is the world"), std::string::npos);
  const Json report = Json::parse(ReadFileToString(RefineReportPath(output)).value());
  EXPECT_EQ(report["world"], "the camera's frame, mm");
  EXPECT_TRUE(report["string_length_measured"]["median_mm"].is_null());
  EXPECT_TRUE(report["reference_frame"].is_null());  // no frame is chosen for a rig
}

// `--labels CAMERA=LABELS.json` (labelme, as `arco track` takes them): the instrument's
// points of one frame, put in every frame in place of keypoints2d's (here made NaN, as
// before `arco track`), with the performer from keypoints2d. Then bad labels: one line
// naming the file, nothing written.
TEST(CalibrateFromInstrument, ReadsLabelsInsteadOfTrackedPoints) {
  TempDir dir;
  const std::string capture = dir / "capture";
  WriteTwoCameraCapture(capture);
  auto truth = calibration::LoadCalibration(capture + "/calibration.json");
  ASSERT_TRUE(truth.ok());
  auto manifest = ReadCaptureManifest(capture);
  ASSERT_TRUE(manifest.ok());
  auto keypoints = ReadCaptureKeypoints2d(capture, *manifest);
  ASSERT_TRUE(keypoints.ok()) << keypoints.status().message();
  const KeypointLayout* layout = FindKeypointLayout(manifest->layout);
  ASSERT_NE(layout, nullptr);
  const std::vector<int>& instrument = *layout->Group("instrument");
  // The labels: frame 11's instrument points as detected (labelme's corner origin), the
  // bow's frog too (ignored); then no instrument points left in keypoints2d.
  constexpr int64_t kLabelsFrame = 11;
  const int64_t row = kLabelsFrame - manifest->frame_first;
  const auto labelme = [&](int v, const std::vector<std::string>& names, int count) {
    Json shapes = Json::array();
    for (int i = 0; i < count; ++i) {
      const int column = layout->Find(names[i]);
      shapes.push_back({{"label", names[i]},
                        {"points",
                         Json::array({Json::array({keypoints->at(row, v, column, 0) + 0.5,
                                                   keypoints->at(row, v, column, 1) + 0.5})})},
                        {"shape_type", "point"}});
    }
    return Json{{"version", "5.3.1"},
                {"shapes", shapes},
                {"imageWidth", kImageWidth},
                {"imageHeight", kImageHeight}}
        .dump(1);
  };
  std::vector<std::string> names;
  for (int column : instrument) names.push_back(layout->names[column]);
  std::vector<std::string> with_bow = names;
  with_bow.push_back("frog");
  std::vector<InstrumentLabelsFile> labels;
  for (int v = 0; v < 2; ++v) {
    const std::string path = dir / (manifest->cameras[v].name + ".json");
    auto file = ParseJsonLenient(labelme(v, with_bow, static_cast<int>(with_bow.size())), path);
    ASSERT_TRUE(file.ok());
    // Camera 1's file also holds a point arco's cello does not have (as SPD's label files
    // hold neck_bottom_l/r): ignored with a warning, as `arco track --labels` does.
    if (v == 1)
      (*file)["shapes"].push_back({{"label", "fingerboard"},
                                   {"points", Json::array({Json::array({10.0, 10.0})})},
                                   {"shape_type", "point"}});
    ASSERT_TRUE(AtomicWriteFile(path, file->dump(1)).ok());
    labels.push_back({manifest->cameras[v].name, path});
  }
  NpyArray<double> without = *keypoints;
  for (int64_t f = 0; f < without.shape[0]; ++f)
    for (int v = 0; v < 2; ++v)
      for (int column : instrument)
        for (int c = 0; c < 3; ++c) without.at(f, v, column, c) = NAN;
  ASSERT_TRUE(WriteNpy(ResolveCapturePath(capture, manifest->keypoints2d), without).ok());

  CalibrationFromInstrumentOptions options = Options(capture, dir / "rig.json");
  options.focal_px = truth->rig.cameras[0].fx;
  options.refine_focal = false;
  auto none = CalibrateFromInstrument(options);  // nothing to take a pose from
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.status().message().find(" never shows 5 "), std::string::npos);
  options.labels = labels;
  options.labels_frame = kLabelsFrame;
  auto result = CalibrateFromInstrument(options);
  ASSERT_TRUE(result.ok()) << result.status().message();
  const RelativeError e = CompareRelative(truth->rig, result->rig);
  std::printf(
      "[ from-instrument --labels ] frame %lld's labels in every frame: PnP in %d frames; "
      "relative pose error %.3f deg, %.2f mm (baseline %+.3f %%); string triangulated %.1f mm\n",
      static_cast<long long>(kLabelsFrame),
      result->shared_frames,
      e.rotation_deg,
      e.position_mm,
      100 * e.baseline_rel,
      result->string_length_measured_mm);
  EXPECT_LE(e.rotation_deg, 2.0);
  EXPECT_LE(std::abs(e.baseline_rel), 0.05);
  EXPECT_NEAR(result->string_length_measured_mm, result->string_length_mm, 35);
  const std::string ignored =
      labels[1].path + ": label \"fingerboard\" is not a point of the cello or the bow (ignored)";
  EXPECT_NE(std::find(result->warnings.begin(), result->warnings.end(), ignored),
            result->warnings.end());

  // Bad labels.
  const std::string output = dir / "bad.json";
  const auto fails = [&](const std::vector<InstrumentLabelsFile>& bad,
                         const std::string& file,
                         const std::string& what) {
    CalibrationFromInstrumentOptions o = options;
    o.output = output;
    o.labels = bad;
    auto r = CalibrateFromInstrument(o);
    ASSERT_FALSE(r.ok()) << what;
    const std::string& m = r.status().message();
    std::printf("%s\n", m.c_str());
    EXPECT_EQ(m.find('\n'), std::string::npos);
    EXPECT_NE(m.find(file), std::string::npos) << m;
    EXPECT_NE(m.find(what), std::string::npos) << m;
    EXPECT_FALSE(fs::exists(output));
    EXPECT_FALSE(fs::exists(dir / "bad.report.json"));
  };
  const std::string cam0 = manifest->cameras[0].name;
  fails({labels[0], {"nosuch", labels[1].path}}, labels[1].path, "camera nosuch is not in");
  fails({labels[0], {cam0, labels[1].path}}, labels[1].path, "is labelled twice");
  fails({labels[0]}, "--labels " + manifest->cameras[1].name, "has no labels");
  const std::string strange = dir / "strange.json";
  {
    // Label names that are no points of the cello: too few points left is an error naming
    // them.
    auto text = ParseJsonLenient(labelme(1, names, static_cast<int>(names.size())), strange);
    ASSERT_TRUE(text.ok());
    for (int i = 0; i + 4 < static_cast<int>(names.size()); ++i)
      (*text)["shapes"][i]["label"] = "fingerboard" + std::to_string(i);
    ASSERT_TRUE(AtomicWriteFile(strange, text->dump()).ok());
  }
  fails({labels[0], {manifest->cameras[1].name, strange}},
        strange,
        "4 of the cello's points are labelled (not its points: fingerboard0, fingerboard1");
  const std::string few = dir / "few.json";
  ASSERT_TRUE(AtomicWriteFile(few, labelme(1, names, 3)).ok());
  fails({labels[0], {manifest->cameras[1].name, few}}, few, "3 of the cello's points are labelled");
  const std::string missing = dir / "missing.json";
  fails({labels[0], {manifest->cameras[1].name, missing}}, missing, "missing.json");
  options.labels_frame = 100000;
  fails(labels, "labels_frame 100000", "is outside the capture's frames");
}

}  // namespace
}  // namespace arco::calibrate
