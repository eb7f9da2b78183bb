// Evaluate() on files: a synthetic capture's truth scored against itself and
// against a perturbed copy; malformed inputs.
#include "arco/eval/evaluate.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "arco/camera/calibration_io.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/synth/capture_writer.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"
#include "arco/util/npy.h"

namespace arco::eval {
namespace {

using arco::testing::PerProcessTempDir;

namespace fs = std::filesystem;

// A short synthetic capture (no audio) written once for all tests.
const std::string& CaptureDir() {
  static const std::string dir = [] {
    const std::string d = PerProcessTempDir() + "/eval_capture";
    auto text =
        ReadFileToString(std::string(ARCO_SHARED_DATA_DIR) + "/spd/cello_1113_scale_camera.xml");
    auto cal = ParseMetashapeXml(*text, "rig.xml");
    synth::SynthOptions o;
    o.max_duration_s = 2.0;
    auto cap = synth::Generate(cal->rig, o);
    EXPECT_TRUE(cap.ok()) << cap.status().message();
    synth::WriteOptions w;
    w.audio = false;
    w.overwrite = true;
    EXPECT_TRUE(synth::WriteCapture(*cap, d, w).ok());
    return d;
  }();
  return dir;
}

// A result folder whose stage `name` holds `points` (and the truth's contact).
std::string MakeResult(const std::string& name, const NpyArray<double>& points, bool with_contact) {
  const std::string dir = PerProcessTempDir() + "/eval_result_" + name;
  fs::remove_all(dir);
  fs::create_directories(dir + "/" + name);
  EXPECT_TRUE(WriteNpy(dir + "/" + name + "/points3d.npy", points).ok());
  Json files = {{"points3d", "points3d.npy"}};
  if (with_contact) {
    fs::copy_file(CaptureDir() + "/truth/contact.csv", dir + "/" + name + "/contact.csv");
    files["contact"] = "contact.csv";
  }
  Json j = {{"format", "arco-result"},
            {"units", "mm"},
            {"stages", {{name, {{"dir", name}, {"files", files}}}}}};
  EXPECT_TRUE(WriteJsonFile(dir + "/result.json", j).ok());
  return dir;
}

TEST(Evaluate, TruthAgainstItselfGivesZeros) {
  auto truth = ReadNpy<double>(CaptureDir() + "/truth/points3d.npy");
  ASSERT_TRUE(truth.ok());
  EvalRequest r;
  r.result_dir = MakeResult("arco", *truth, true);
  r.truth = CaptureDir() + "/truth";
  auto report = Evaluate(r);
  ASSERT_TRUE(report.ok()) << report.status().message();
  ASSERT_EQ(report->methods.size(), 1u);
  const MethodMetrics& m = report->methods[0];
  EXPECT_EQ(m.method, "arco");
  EXPECT_GT(report->contact_frames, 10);
  EXPECT_EQ(m.mpjpe_hand_mm, 0.0);
  EXPECT_EQ(m.mpjpe_note_finger_mm, 0.0);
  EXPECT_LT(m.contact_deviation_mm, 1e-3);  // the truth tip is on the contact within IK precision
  EXPECT_EQ(m.string_accuracy, 1.0);
  EXPECT_EQ(m.finger_accuracy, 1.0);
  EXPECT_EQ(m.joint_limit_violations, 0);
  EXPECT_EQ(m.mpjpe_body_mm, 0.0);
  EXPECT_EQ(m.instrument_error_mm, 0.0);
  EXPECT_EQ(m.string_error_mm, 0.0);
  const Json j = report->ToJson(r.metrics);
  EXPECT_EQ(j["methods"]["arco"]["mpjpe_hand_mm"], 0.0);
  EXPECT_EQ(j["methods"]["arco"]["pck_5mm"], 1.0);
  EXPECT_NE(report->MarkdownTable(r.metrics).find("| arco | 0.00 | 0.00 |"), std::string::npos);
}

TEST(Evaluate, ShiftedLeftHandKeepsAlignedMpjpeButNotContactDeviation) {
  auto truth = ReadNpy<double>(CaptureDir() + "/truth/points3d.npy");
  ASSERT_TRUE(truth.ok());
  NpyArray<double> moved = *truth;
  for (int64_t f = 0; f < moved.shape[0]; ++f) {
    for (int k = 91; k < 112; ++k) moved.at(f, k, 2) += 10.0;  // whole left hand 10 mm along z
  }
  // The result has only the capture layout (142 points), as triangulation writes.
  NpyArray<double> cut;
  cut.shape = {moved.shape[0], 142, 3};
  for (int64_t f = 0; f < moved.shape[0]; ++f) {
    for (int p = 0; p < 142; ++p) {
      for (int c = 0; c < 3; ++c) cut.data.push_back(moved.at(f, p, c));
    }
  }
  EvalRequest r;
  r.result_dir = MakeResult("triangulation", cut, false);
  r.truth = CaptureDir() + "/truth";
  auto report = Evaluate(r);
  ASSERT_TRUE(report.ok()) << report.status().message();
  const MethodMetrics& m = report->methods[0];
  EXPECT_NEAR(m.mpjpe_hand_mm, 0.0, 1e-9);
  EXPECT_NEAR(m.contact_deviation_mm, 10.0, 1e-3);
  EXPECT_NEAR(m.mpjpe_body_mm, 10.0 * 21 / 133, 1e-9);  // 133 body points, 21 moved
  EXPECT_TRUE(std::isnan(m.string_accuracy));
  EXPECT_TRUE(std::isnan(m.string_error_mm));  // no string points in the result
}

TEST(Evaluate, BadInput) {
  EvalRequest r;
  r.result_dir = PerProcessTempDir() + "/no_such_result";
  r.truth = CaptureDir() + "/truth";
  EXPECT_FALSE(Evaluate(r).ok());
  auto truth = ReadNpy<double>(CaptureDir() + "/truth/points3d.npy");
  NpyArray<double> short_result = *truth;
  short_result.shape[0] = 1;
  short_result.data.resize(static_cast<size_t>(short_result.shape[1] * 3));
  r.result_dir = MakeResult("vision", short_result, false);
  auto report = Evaluate(r);
  ASSERT_FALSE(report.ok());
  EXPECT_NE(report.status().message().find("frames but the truth has"), std::string::npos);
  const std::string bad = PerProcessTempDir() + "/bad_contact.csv";
  ASSERT_TRUE(AtomicWriteFile(bad, "frame,string,finger\n0,1,1\n").ok());
  EXPECT_FALSE(ReadContactCsv(bad, 3).ok());
  ASSERT_TRUE(AtomicWriteFile(
                  bad, "frame,string,finger,contact_x_mm,contact_y_mm,contact_z_mm\n0,9,1,0,0,0\n")
                  .ok());
  EXPECT_FALSE(ReadContactCsv(bad, 3).ok());
}

TEST(DefaultLeftHandLimits, TruthHandsHaveNoViolationsAndBentFingersDo) {
  auto truth = ReadNpy<double>(CaptureDir() + "/truth/points3d.npy");
  ASSERT_TRUE(truth.ok());
  PointSequence s(static_cast<int>(truth->shape[0]), static_cast<int>(truth->shape[1]));
  s.xyz = truth->data;
  const HandJointLimitsDeg limits = DefaultLeftHandLimits();
  EXPECT_EQ(CountJointLimitViolations(s, kLeftHandFirst, true, limits, 5.0), 0);
  // Bend every (curled) index tip back within its plane to a 60 degree DIP hyperextension,
  // beyond the limit (real players hyperextend the DIP, but not that far).
  for (int f = 0; f < s.num_frames; ++f) {
    const Eigen::Vector3d pip = s.at(f, kLeftHandFirst + 6), dip = s.at(f, kLeftHandFirst + 7),
                          tip = s.at(f, kLeftHandFirst + 8);
    const Eigen::Vector3d u = (dip - pip).normalized();
    const Eigen::Vector3d palmar = (tip - dip) - (tip - dip).dot(u) * u;
    if (palmar.norm() < 1e-3) continue;  // a straight finger: no plane
    const Eigen::Vector3d w = palmar.normalized();
    const double length = (tip - dip).norm();
    s.set(f, kLeftHandFirst + 8, dip + length * (0.5 * u - std::sqrt(0.75) * w));
  }
  EXPECT_GT(CountJointLimitViolations(s, kLeftHandFirst, true, limits, 5.0), s.num_frames / 2);
}

TEST(EvalRequest, NumbersOutsideTheirRangesAreErrorsBeforeAnyFileIsRead) {
  EvalRequest r;
  r.result_dir = "does-not-exist";
  r.metrics.pck_thresholds_mm = {10, -5};
  auto report = Evaluate(r);
  ASSERT_FALSE(report.ok());
  EXPECT_NE(report.status().message().find("pck_thresholds_mm"), std::string::npos);
  r.metrics.pck_thresholds_mm = {10};
  r.joint_limit_tolerance_deg = std::nan("");
  EXPECT_NE(r.Validate().message().find("joint_limit_tolerance_deg"), std::string::npos);
  r.joint_limit_tolerance_deg = 5;
  r.truth_frames = {-3};
  EXPECT_NE(r.Validate().message().find("truth_frames"), std::string::npos);
  r.truth_frames = {0, 12};
  EXPECT_TRUE(r.Validate().ok());
}

}  // namespace
}  // namespace arco::eval

namespace arco::eval {
namespace {

// Real-data mode: labelled frames (as `arco triangulate --view` writes them)
// become the truth of those frames only; points are matched by name.
TEST(Evaluate, LabelledFramesAsTruth) {
  auto truth = ReadNpy<double>(CaptureDir() + "/truth/points3d.npy");
  ASSERT_TRUE(truth.ok());
  NpyArray<double> cut;
  const int64_t frames = truth->shape[0];
  cut.shape = {frames, 142, 3};
  for (int64_t f = 0; f < frames; ++f) {
    for (int p = 0; p < 142; ++p) {
      for (int c = 0; c < 3; ++c) cut.data.push_back(truth->at(f, p, c));
    }
  }
  const std::string dir = MakeResult("triangulation", cut, false);
  // The result manifest needs the keypoint names and frame numbering.
  auto rj = ReadJsonFile(dir + "/result.json");
  ASSERT_TRUE(rj.ok());
  Json j = *rj;
  j["frames"] = {{"first", 1}, {"count", frames}};
  j["keypoint_names"] = FindKeypointLayout("spd_cello")->names;
  ASSERT_TRUE(WriteJsonFile(dir + "/result.json", j).ok());
  // Frame 11 labels two instrument points; one is 3 mm off the result.
  const Eigen::Vector3d nut(truth->at(10, 134, 0), truth->at(10, 134, 1), truth->at(10, 134, 2));
  const Eigen::Vector3d tip(
      truth->at(10, 141, 0), truth->at(10, 141, 1), truth->at(10, 141, 2) + 3.0);
  const Json labels = {{"units", "mm"},
                       {"points",
                        {{{"name", "nut_l"}, {"xyz", {nut.x(), nut.y(), nut.z()}}},
                         {{"name", "tip_plate"}, {"xyz", {tip.x(), tip.y(), tip.z()}}},
                         {{"name", "not_a_keypoint"}, {"xyz", {0, 0, 0}}}}}};
  const std::string path = PerProcessTempDir() + "/labels11.json";
  ASSERT_TRUE(WriteJsonFile(path, labels).ok());
  EvalRequest r;
  r.result_dir = dir;
  r.labels = {path};
  r.truth_frames = {11};
  auto report = Evaluate(r);
  ASSERT_TRUE(report.ok()) << report.status().message();
  EXPECT_EQ(report->truth_kind, "labels");
  EXPECT_EQ(report->truth_frames, 1);
  EXPECT_EQ(report->contact_frames, 0);
  const MethodMetrics& m = report->methods[0];
  EXPECT_NEAR(m.instrument_error_mm, 1.5, 1e-9);  // (0 + 3) / 2
  EXPECT_TRUE(std::isnan(m.mpjpe_hand_mm));
  EXPECT_TRUE(std::isnan(m.contact_deviation_mm));
  r.truth_frames = {frames + 5};
  EXPECT_FALSE(Evaluate(r).ok());
  r.truth_frames = {};
  EXPECT_FALSE(Evaluate(r).ok());
}

}  // namespace
}  // namespace arco::eval
