#include "arco/calibrate/calibration_from_instrument.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "arco/calibration/calibration_file.h"
#include "arco/geometry/rotation.h"
#include "arco/geometry/transform.h"
#include "arco/instrument/instrument_model.h"
#include "arco/instrument/nominal_keypoints.h"
#include "arco/media/video_reader.h"
#include "arco/mocap/capture.h"
#include "arco/mocap/labelme.h"
#include "arco/mocap/triangulate_point.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/track/one_view_pnp.h"
#include "arco/util/output_set.h"
#include "arco/util/stats.h"

namespace arco::calibrate {
namespace {

// Shared frames the medoid looks at, at most (evenly spread): it is quadratic in them.
constexpr int kMaxMedoidFrames = 300;

// One view's PnP solution in one frame.
struct ViewPose {
  bool valid = false;
  RigidMatrix3d cam_from_instrument;
  double rms_px = 0;
};

// One view's pose of the instrument: EPnP in RANSAC, then Levenberg-Marquardt on the
// inliers (undistorted pinhole: the intrinsics here have no distortion).
ViewPose SolveView(const std::vector<cv::Point3d>& object,
                   const std::vector<cv::Point2d>& image,
                   const cv::Matx33d& K,
                   double gate_px) {
  ViewPose pose;
  std::vector<Eigen::Vector3d> object_points;
  std::vector<Eigen::Vector2d> pixels;
  for (const cv::Point3d& p : object) object_points.emplace_back(p.x, p.y, p.z);
  for (const cv::Point2d& p : image) pixels.emplace_back(p.x, p.y);
  Eigen::Matrix3d k;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) k(r, c) = K(r, c);
  const std::optional<track::OneViewPnp> pnp =
      track::EpnpInRansac(object_points, pixels, k, gate_px, 4);
  if (!pnp) return pose;
  const std::vector<int>& inliers = pnp->inliers;
  cv::Mat rvec =
      (cv::Mat_<double>(3, 1) << pnp->angle_axis.x(), pnp->angle_axis.y(), pnp->angle_axis.z());
  cv::Mat tvec =
      (cv::Mat_<double>(3, 1) << pnp->translation.x(), pnp->translation.y(), pnp->translation.z());
  std::vector<cv::Point3d> in_object;
  std::vector<cv::Point2d> in_image;
  for (int i : inliers) in_object.push_back(object[i]), in_image.push_back(image[i]);
  cv::solvePnP(in_object, in_image, K, cv::noArray(), rvec, tvec, true, cv::SOLVEPNP_ITERATIVE);
  std::vector<cv::Point2d> projected;
  cv::projectPoints(in_object, rvec, tvec, K, cv::noArray(), projected);
  double sq = 0;
  for (size_t i = 0; i < projected.size(); ++i) {
    const cv::Point2d d = projected[i] - in_image[i];
    sq += d.dot(d);
  }
  pose.rms_px = std::sqrt(sq / projected.size());
  cv::Matx33d R;
  cv::Rodrigues(rvec, R);
  for (int r = 0; r < 3; ++r) {
    pose.cam_from_instrument.translation[r] = tvec.at<double>(r);
    for (int c = 0; c < 3; ++c) pose.cam_from_instrument.rotation(r, c) = R(r, c);
  }
  // In front of the camera, and agreeing with its inliers.
  pose.valid = pose.cam_from_instrument.translation.z() > 0 && pose.rms_px <= gate_px;
  return pose;
}

// Camera c's pose in camera 0's frame: cam_c_from_cam_0.
struct Relative {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d centre_mm;  // camera c's centre in camera 0's frame
};

Relative RelativePose(const RigidMatrix3d& c_from_instrument,
                      const RigidMatrix3d& zero_from_instrument) {
  Relative r;
  r.rotation = c_from_instrument.rotation * zero_from_instrument.rotation.transpose();
  const Eigen::Vector3d t =
      c_from_instrument.translation - r.rotation * zero_from_instrument.translation;
  r.centre_mm = -r.rotation.transpose() * t;
  return r;
}

// The labelled instrument points of every camera (labelme files, mocap/labelme.h) into
// every frame of `keypoints` (the capture's frames; score 1), in place of its instrument
// points: a starting point before anything is tracked. Every check first, each error one
// line naming the file.
Status PutLabels(const CalibrationFromInstrumentOptions& options,
                 const CaptureManifest& manifest,
                 const std::string& manifest_file,
                 const Rig& rig,
                 const KeypointLayout& layout,
                 NpyArray<double>* keypoints,
                 std::vector<std::string>* warnings) {
  const int64_t first = manifest.frame_first, last = first + manifest.frame_count - 1;
  const int64_t frame = options.labels_frame >= 0 ? options.labels_frame : first;
  if (frame < first || frame > last)
    return Status::Error("labels_frame " + std::to_string(frame) +
                         " is outside the capture's frames " + std::to_string(first) + ":" +
                         std::to_string(last) + " (" + manifest_file + ")");
  const std::vector<int>* instrument = layout.Group("instrument");
  const std::vector<int>* bow = layout.Group("bow");
  if (instrument == nullptr || instrument->empty())
    return Status::Error(manifest_file + ": layout " + layout.name + " has no instrument points");
  std::string expected;
  for (int column : *instrument) expected += (expected.empty() ? "" : ", ") + layout.names[column];
  const int views = static_cast<int>(manifest.cameras.size());
  // Per view, the labelled pixel of each instrument column (NaN: not labelled).
  std::vector<std::vector<Eigen::Vector2d>> labelled(views);
  std::vector<std::string> file_of(views);
  for (const InstrumentLabelsFile& file : options.labels) {
    const int v = manifest.FindCamera(file.camera);
    if (v < 0) {
      std::string cameras;
      for (const CaptureCamera& c : manifest.cameras)
        cameras += (cameras.empty() ? "" : ", ") + c.name;
      return Status::Error(file.path + ": camera " + file.camera + " is not in " + manifest_file +
                           " (cameras: " + cameras + ")");
    }
    if (!file_of[v].empty())
      return Status::Error(file.path + ": camera " + file.camera + " is labelled twice (also " +
                           file_of[v] + ")");
    file_of[v] = file.path;
    // The labelled frame is the capture's, as `arco track`'s: a camera off the capture's
    // clock shows it in its own frame nearest that moment.
    const int64_t own = manifest.cameras[v].OnCaptureClock()
                            ? frame
                            : std::llround(manifest.CameraFrameAt(v, static_cast<double>(frame)));
    if (own < first || own > last || manifest.VideoFrameNumber(v, own) < 0)
      return Status::Error(file.path + ": camera " + file.camera + " did not record frame " +
                           std::to_string(frame) + " of the capture (--labels-frame)");
    ARCO_ASSIGN_OR_RETURN(const LabelmeAnnotation a, ReadLabelme(file.path));
    const Camera& cam = rig.cameras[v];
    if ((a.image_width > 0 && a.image_width != cam.width) ||
        (a.image_height > 0 && a.image_height != cam.height))
      return Status::Error(file.path + ": image is " + std::to_string(a.image_width) + "x" +
                           std::to_string(a.image_height) + ", camera " + cam.name + " is " +
                           std::to_string(cam.width) + "x" + std::to_string(cam.height) +
                           " (label the frame as turned by rotate_deg)");
    labelled[v].assign(instrument->size(), Eigen::Vector2d::Constant(NAN));
    int count = 0;
    std::string ignored;  // labels that are no point of the instrument or the bow
    for (const LabeledPoint& p : a.points) {
      const int column = layout.Find(CanonicalKeypointName(p.label));
      const auto it = std::find(instrument->begin(), instrument->end(), column);
      if (it == instrument->end()) {
        if (column >= 0 && bow != nullptr &&
            std::find(bow->begin(), bow->end(), column) != bow->end())
          continue;  // the bow's frog and tip, for `arco track`
        // Ignored with a warning, as `arco track --labels` does: other tools' label sets
        // (SPD's neck_bottom_l/r) hold points arco's model does not have. Too few known
        // points left is still an error (below).
        warnings->push_back(file.path + ": label \"" + p.label + "\" is not a point of the " +
                            manifest.instrument + " or the bow (ignored)");
        ignored += (ignored.empty() ? "" : ", ") + p.label;
        continue;
      }
      if (!(p.pixel.x() >= -0.5 && p.pixel.y() >= -0.5 && p.pixel.x() < cam.width - 0.5 &&
            p.pixel.y() < cam.height - 0.5))
        return Status::Error(file.path + ": label " + p.label + " at (" + NumberText(p.pixel.x()) +
                             ", " + NumberText(p.pixel.y()) + ") is outside the " +
                             std::to_string(cam.width) + "x" + std::to_string(cam.height) +
                             " image of camera " + cam.name);
      labelled[v][it - instrument->begin()] = p.pixel;
      ++count;
    }
    if (count < options.min_points)
      return Status::Error(
          file.path + ": " + std::to_string(count) + " of the " + manifest.instrument +
          "'s points are labelled" + (ignored.empty() ? "" : " (not its points: " + ignored + ")") +
          ", a camera's pose needs " + std::to_string(options.min_points) + " (" + expected + ")");
  }
  for (int v = 0; v < views; ++v)
    if (file_of[v].empty())
      return Status::Error("labels: camera " + manifest.cameras[v].name +
                           " has no labels (give --labels " + manifest.cameras[v].name +
                           "=LABELS.json)");
  NpyArray<double>& k = *keypoints;
  for (int64_t f = 0; f < k.shape[0]; ++f)
    for (int v = 0; v < views; ++v)
      for (size_t i = 0; i < instrument->size(); ++i) {
        const Eigen::Vector2d& x = labelled[v][i];
        const bool ok = std::isfinite(x.x());
        k.at(f, v, (*instrument)[i], 0) = ok ? x.x() : NAN;
        k.at(f, v, (*instrument)[i], 1) = ok ? x.y() : NAN;
        k.at(f, v, (*instrument)[i], 2) = ok ? 1.0 : NAN;
      }
  return Status::Ok();
}

}  // namespace

Status CalibrationFromInstrumentOptions::Validate() const {
  if (capture_dir.empty()) return Status::Error("capture_dir: no capture folder given");
  if (output.empty()) return Status::Error("output: no calibration file given");
  if (focal_px != 0)
    ARCO_RETURN_IF_ERROR(CheckInRange("focal_px", focal_px, kFromInstrumentFocalRangePx));
  if (fov_deg != 0)
    ARCO_RETURN_IF_ERROR(CheckInRange("fov_deg", fov_deg, kFromInstrumentFovRangeDeg));
  if (focal_px != 0 && fov_deg != 0)
    return Status::Error("focal_px, fov_deg: give one of them, not both");
  ARCO_RETURN_IF_ERROR(CheckInRange("image_width", image_width, kFromInstrumentImageSideRange));
  ARCO_RETURN_IF_ERROR(CheckInRange("image_height", image_height, kFromInstrumentImageSideRange));
  if ((image_width == 0) != (image_height == 0))
    return Status::Error("image_width, image_height: give both or neither");
  ARCO_RETURN_IF_ERROR(CheckInRange("min_score", min_score, Closed(0, 1)));
  ARCO_RETURN_IF_ERROR(CheckInRange("min_points", min_points, kFromInstrumentPointsRange));
  ARCO_RETURN_IF_ERROR(CheckInRange("pnp_gate_px", pnp_gate_px, kFromInstrumentGateRangePx));
  ARCO_RETURN_IF_ERROR(CheckInRange("max_frames", max_frames, kRefineMaxFramesRange));
  ARCO_RETURN_IF_ERROR(CheckInRange("max_iterations", max_iterations, kRefineIterationsRange));
  if (labels_frame < -1) return Status::Error("labels_frame must be -1 (the first) or >= 0");
  for (const InstrumentLabelsFile& l : labels)
    if (l.camera.empty() || l.path.empty())
      return Status::Error("labels: a camera and a file each (CAMERA=LABELS.json)");
  return Status::Ok();
}

Json CalibrationFromInstrumentSummary::ToJson() const {
  Json j;
  j["capture"] = capture_dir;
  j["output"] = output;
  j["instrument"] = instrument;
  j["world"] = cameras.size() == 1 ? "the camera's frame, mm" : "the first camera's frame, mm";
  j["focal_source"] = focal_source;
  j["shared_frames"] = shared_frames;
  // One camera chooses no frame for an initial rig: its frame is the world.
  j["reference_frame"] = cameras.size() == 1 ? Json() : Json(reference_frame);
  j["string_length_mm"] = string_length_mm;
  j["string_length_initial_mm"] = string_length_initial_mm;
  j["string_length_error_initial_mm"] = string_length_initial_mm - string_length_mm;
  j["string_length_measured"] = {{"median_mm", string_length_measured_mm},
                                 {"error_mm", string_length_measured_mm - string_length_mm},
                                 {"spread_mm", string_length_spread_mm},
                                 {"frames", string_length_frames}};
  j["rms_initial_px"] = rms_initial_px;
  j["rms_px"] = rms_px;
  j["cameras"] = Json::array();
  for (const FromInstrumentCamera& c : cameras)
    j["cameras"].push_back({{"name", c.name},
                            {"width", c.width},
                            {"height", c.height},
                            {"size_source", c.size_source},
                            {"initial_focal_px", c.initial_focal_px},
                            {"focal_px", c.focal_px},
                            {"pnp_frames", c.pnp_frames},
                            {"pnp_rms_px", c.pnp_rms_px},
                            {"relative_spread_deg", c.relative_spread_deg},
                            {"relative_spread_mm", c.relative_spread_mm}});
  j["refinement"] = refinement.ToJson();
  j["warnings"] = warnings;
  return j;
}

namespace {

// The calibration file and its report, both or neither (OutputSet).
Status WriteCalibrationAndReport(const std::string& output,
                                 CalibrationFormat format,
                                 const std::string& report_file,
                                 const CalibrationFromInstrumentSummary& summary) {
  OutputSet outputs;
  ARCO_ASSIGN_OR_RETURN(const std::string calibration_tmp, outputs.AddFile(output));
  ARCO_ASSIGN_OR_RETURN(const std::string report_tmp, outputs.AddFile(report_file));
  ARCO_RETURN_IF_ERROR(calibration::SaveCalibration(calibration_tmp, summary.rig, format));
  {
    std::ofstream out(report_tmp);
    out << summary.ToJson().dump(2) << "\n";
    if (!out) return Status::Error(report_file + ": cannot write");
  }
  return outputs.Commit();
}

// One phone: nothing relates it to another camera and one view measures no length, so the
// camera's own frame is the world (the identity pose) and its intrinsics are what step 1
// gave; the per-frame PnP (step 2) only reports how well the instrument's model fits its
// points (`arco run` poses the instrument per frame itself: track/monocular_lift.h).
StatusOr<CalibrationFromInstrumentSummary> OneCameraCalibration(
    const CalibrationFromInstrumentOptions& options,
    CalibrationFormat format,
    const std::string& report_file,
    const Rig& rig,
    const std::vector<std::string>& label_warnings,
    CalibrationFromInstrumentSummary summary) {
  summary.rig = rig;
  summary.shared_frames = summary.cameras[0].pnp_frames;
  summary.string_length_initial_mm = summary.string_length_mm;
  summary.rms_initial_px = summary.rms_px = summary.cameras[0].pnp_rms_px;
  summary.cameras[0].focal_px = rig.cameras[0].fx;
  summary.string_length_measured_mm = summary.string_length_spread_mm =
      std::numeric_limits<double>::quiet_NaN();
  summary.string_length_frames = 0;
  summary.warnings = label_warnings;
  summary.warnings.push_back(
      "one camera: its frame is the world and nothing is refined or measured; the "
      "instrument's real size will set the scale (`arco run` on one camera)");
  if (options.focal_px == 0 && options.fov_deg == 0)
    summary.warnings.push_back("the focal length is a phone's default (" +
                               NumberText(kPhoneFovDeg) +
                               " deg); give --focal-px or --fov-deg when known: one view "
                               "does not measure it");
  ARCO_RETURN_IF_ERROR(WriteCalibrationAndReport(options.output, format, report_file, summary));
  return summary;
}

}  // namespace

StatusOr<CalibrationFromInstrumentSummary> CalibrateFromInstrument(
    const CalibrationFromInstrumentOptions& options, Progress& progress) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  ARCO_ASSIGN_OR_RETURN(const CalibrationFormat format, CalibrationOutputFormat(options.output));
  const std::string report_file = RefineReportPath(options.output);
  for (const std::string& path : {options.output, report_file}) {
    ARCO_RETURN_IF_ERROR(CheckOutputFile(path));
    if (!options.overwrite && std::filesystem::exists(path))
      return Status::Error(path + ": exists; give --overwrite to replace it");
  }
  CaptureManifest manifest;
  if (options.capture_manifest) {
    manifest = *options.capture_manifest;
  } else {
    ARCO_ASSIGN_OR_RETURN(manifest, ReadCaptureManifest(options.capture_dir));
  }
  const std::string manifest_file = options.capture_dir + "/capture.json";
  if (manifest.instrument.empty() || manifest.instrument == "none")
    return Status::Error(manifest_file +
                         ": no instrument; calibrating from the instrument needs its model "
                         "(capture new --instrument)");
  if (manifest.keypoints2d.empty())
    return Status::Error(manifest_file + ": no keypoints2d (the instrument's 2D points)");
  const int num_views = static_cast<int>(manifest.cameras.size());
  ARCO_ASSIGN_OR_RETURN(const InstrumentModel model, InstrumentModel::Create(manifest.instrument));
  const KeypointLayout* layout = FindKeypointLayout(manifest.layout);
  if (layout == nullptr)
    return Status::Error(manifest_file + ": unknown layout '" + manifest.layout + "'");

  CalibrationFromInstrumentSummary summary;
  summary.capture_dir = options.capture_dir;
  summary.output = options.output;
  summary.instrument = manifest.instrument;
  summary.string_length_mm = model.string_length_mm();

  // 1. Intrinsics.
  Rig rig;
  rig.units = "mm";
  double fov_deg = options.fov_deg > 0 ? options.fov_deg : kPhoneFovDeg;
  summary.focal_source = options.focal_px > 0  ? "--focal-px"
                         : options.fov_deg > 0 ? "--fov-deg " + NumberText(fov_deg)
                                               : "phone default (" + NumberText(fov_deg) +
                                                     " deg across the longer side)";
  for (const CaptureCamera& view : manifest.cameras) {
    FromInstrumentCamera report;
    report.name = view.name;
    int width = 0, height = 0;
    if (options.image_width > 0) {
      width = options.image_width, height = options.image_height;
      report.size_source = "--image-size";
    } else {
      if (view.video.empty())
        return Status::Error(manifest_file + ": camera " + view.name +
                             " has no video to read its image size from (give --image-size)");
      const std::string video = ResolveCapturePath(options.capture_dir, view.video);
      auto reader = media::VideoReader::Open(video);
      if (!reader.ok()) return reader.status().WithContext("camera " + view.name);
      width = reader->properties().width;
      height = reader->properties().height;
      if (view.rotate_deg == 90 || view.rotate_deg == 270) std::swap(width, height);
      report.size_source = "video";
    }
    Camera cam = CentredPinhole(
        view.name,
        width,
        height,
        options.focal_px > 0 ? options.focal_px : FocalPxFromFov(width, height, fov_deg));
    cam.serial = view.serial;
    report.initial_focal_px = cam.fx;
    report.width = cam.width, report.height = cam.height;
    rig.cameras.push_back(cam);
    summary.cameras.push_back(report);
  }

  // 2. PnP per view and frame.
  // Checked and parsed from one read (CheckCaptureKeypoints2d's checks and messages).
  ARCO_ASSIGN_OR_RETURN(const FileBytes keypoint_bytes,
                        ReadCaptureKeypoints2dBytes(options.capture_dir, manifest));
  ARCO_ASSIGN_OR_RETURN(
      NpyArray<double> keypoints,
      ParseCaptureKeypoints2d(keypoint_bytes.view(), options.capture_dir, manifest));
  std::string keypoints_file = ResolveCapturePath(options.capture_dir, manifest.keypoints2d);
  const int64_t frames = keypoints.shape[0];
  if (keypoints.shape[2] != layout->size())
    return Status::Error(keypoints_file + ": " + std::to_string(keypoints.shape[2]) +
                         " keypoints per view, layout " + manifest.layout + " has " +
                         std::to_string(layout->size()));
  std::vector<std::string> label_warnings;
  if (!options.labels.empty()) {
    ARCO_RETURN_IF_ERROR(
        PutLabels(options, manifest, manifest_file, rig, *layout, &keypoints, &label_warnings));
    // Messages about the instrument's points name the labels.
    keypoints_file.clear();
    for (const InstrumentLabelsFile& l : options.labels)
      keypoints_file += (keypoints_file.empty() ? "" : ", ") + l.path;
  }
  const std::vector<Eigen::Vector3d> nominal = NominalPoseKeypointsInInstrument(model);
  std::vector<std::pair<int, cv::Point3d>> rigid;  // layout column, nominal point
  for (int k : model.rigid_keypoints()) {
    const int column = layout->Find(model.keypoint_names()[k]);
    if (column >= 0 && nominal[k].allFinite())
      rigid.emplace_back(column, cv::Point3d(nominal[k].x(), nominal[k].y(), nominal[k].z()));
  }
  if (static_cast<int>(rigid.size()) < options.min_points)
    return Status::Error(manifest_file + ": layout " + manifest.layout + " has " +
                         std::to_string(rigid.size()) + " of the " + manifest.instrument +
                         "'s rigid points, a pose needs " + std::to_string(options.min_points));
  std::vector<std::vector<ViewPose>> poses(num_views, std::vector<ViewPose>(frames));
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (int v = 0; v < num_views; ++v) {
    const Camera& cam = rig.cameras[v];
    const cv::Matx33d K(cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
    std::vector<double> rms;
    for (int64_t f = 0; f < frames; ++f) {
      object.clear(), image.clear();
      for (const auto& [column, point] : rigid) {
        const double x = keypoints.at(f, v, column, 0), y = keypoints.at(f, v, column, 1),
                     score = keypoints.at(f, v, column, 2);
        if (!std::isfinite(x) || !std::isfinite(y) || !(score >= options.min_score)) continue;
        object.push_back(point);
        image.emplace_back(x, y);
      }
      if (static_cast<int>(object.size()) < options.min_points) continue;
      poses[v][f] = SolveView(object, image, K, options.pnp_gate_px);
      if (poses[v][f].valid) rms.push_back(poses[v][f].rms_px);
    }
    summary.cameras[v].pnp_frames = static_cast<int>(rms.size());
    summary.cameras[v].pnp_rms_px = UpperMedian(rms);
    if (rms.empty())
      return Status::Error(keypoints_file + ": camera " + cam.name + " never shows " +
                           std::to_string(options.min_points) + " of the " + manifest.instrument +
                           "'s points with a score of at least " + NumberText(options.min_score) +
                           " that a PnP pose agrees with (its pose comes from them)");
  }

  if (num_views == 1)
    return OneCameraCalibration(
        options, format, report_file, rig, label_warnings, std::move(summary));

  // 3. The frames every camera has a pose in; the medoid of their relative poses.
  std::vector<int64_t> shared;
  for (int64_t f = 0; f < frames; ++f) {
    bool all = true;
    for (int v = 0; v < num_views; ++v) all = all && poses[v][f].valid;
    if (all) shared.push_back(f);
  }
  summary.shared_frames = static_cast<int>(shared.size());
  if (shared.empty()) {
    std::string counts;
    for (const FromInstrumentCamera& c : summary.cameras)
      counts += (counts.empty() ? "" : ", ") + c.name + " " + std::to_string(c.pnp_frames);
    return Status::Error(keypoints_file +
                         ": no frame where every camera has a pose of the instrument "
                         "(frames with one: " +
                         counts + ")");
  }
  if (static_cast<int>(shared.size()) > kMaxMedoidFrames) {
    std::vector<int64_t> spread;
    for (int i = 0; i < kMaxMedoidFrames; ++i)
      spread.push_back(
          shared[static_cast<size_t>(i) * (shared.size() - 1) / (kMaxMedoidFrames - 1)]);
    shared = spread;
  }
  const int n = static_cast<int>(shared.size());
  // relative[v][i]: camera v in camera 0's frame in shared frame i.
  std::vector<std::vector<Relative>> relative(num_views);
  for (int v = 1; v < num_views; ++v)
    for (int64_t f : shared)
      relative[v].push_back(
          RelativePose(poses[v][f].cam_from_instrument, poses[0][f].cam_from_instrument));
  // Degrees plus centimetres: a degree of a camera 2-3 m away moves its view about as
  // much as a centimetre.
  auto distance = [&](int i, int j) {
    double d = 0;
    for (int v = 1; v < num_views; ++v)
      d += RotationAngleBetween(relative[v][i].rotation, relative[v][j].rotation) * 180 / M_PI +
           0.1 * (relative[v][i].centre_mm - relative[v][j].centre_mm).norm();
    return d;
  };
  int best = 0;
  double best_cost = std::numeric_limits<double>::infinity();
  std::vector<double> d(n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) d[j] = distance(i, j);
    const double cost = UpperMedian(d);
    if (cost < best_cost) best_cost = cost, best = i;
  }
  summary.reference_frame = manifest.frame_first + shared[best];
  for (int v = 1; v < num_views; ++v) {
    Camera& cam = rig.cameras[v];
    const Relative& r = relative[v][best];
    cam.cam_from_world.rotation = r.rotation;
    cam.cam_from_world.translation = -r.rotation * r.centre_mm;
    std::vector<double> deg, mm;
    for (int i = 0; i < n; ++i) {
      deg.push_back(RotationAngleBetween(relative[v][i].rotation, r.rotation) * 180 / M_PI);
      mm.push_back((relative[v][i].centre_mm - r.centre_mm).norm());
    }
    summary.cameras[v].relative_spread_deg = UpperMedian(deg);
    summary.cameras[v].relative_spread_mm = UpperMedian(mm);
  }

  // 4. Bundle adjustment with the performer and the instrument (calibration_refine.h).
  CalibrationRefineOptions refine;
  refine.capture_dir = options.capture_dir;
  refine.capture_manifest = manifest;
  refine.calibration = "the rig from the instrument's PnP poses";
  refine.input_rig = rig;
  refine.input_keypoints = &keypoints;
  refine.write = false;
  refine.reference_camera = rig.cameras[0].name;
  refine.refine_focal = options.refine_focal;
  refine.min_score = options.min_score;
  refine.min_views = 2;
  refine.max_frames = options.max_frames;
  refine.max_iterations = options.max_iterations;
  ARCO_ASSIGN_OR_RETURN(summary.refinement, RefineCalibration(refine, progress));
  summary.rig = summary.refinement.rig;
  summary.string_length_initial_mm = summary.refinement.string_length_before_mm;
  summary.rms_initial_px = summary.refinement.rms_before_px;
  summary.rms_px = summary.refinement.rms_after_px;
  for (int v = 0; v < num_views; ++v) summary.cameras[v].focal_px = summary.rig.cameras[v].fx;
  // The string length as the refined rig measures it frame by frame (triangulated nut and
  // bridge edges, not the template the bundle adjustment held at the model's length).
  {
    TriangulationOptions triangulation;
    triangulation.min_score = options.min_score;
    const Triangulator triangulator(summary.rig, triangulation);
    const int columns[4] = {layout->Find("nut_l"),
                            layout->Find("nut_r"),
                            layout->Find("bridge_l"),
                            layout->Find("bridge_r")};
    std::vector<double> lengths;
    std::vector<PointObservation> observations;
    for (int64_t f = 0; f < frames; ++f) {
      Eigen::Vector3d p[4];
      bool all = true;
      for (int k = 0; k < 4 && all; ++k) {
        observations.clear();
        for (int v = 0; v < num_views && columns[k] >= 0; ++v)
          observations.push_back({v,
                                  Eigen::Vector2d(keypoints.at(f, v, columns[k], 0),
                                                  keypoints.at(f, v, columns[k], 1)),
                                  keypoints.at(f, v, columns[k], 2)});
        const auto point = triangulator.Triangulate(observations);
        all = point.has_value();
        if (all) p[k] = point->point_in_world;
      }
      if (all) lengths.push_back((0.5 * (p[0] + p[1]) - 0.5 * (p[2] + p[3])).norm());
    }
    summary.string_length_frames = static_cast<int>(lengths.size());
    summary.string_length_measured_mm = UpperMedian(lengths);
    for (double& l : lengths) l = std::abs(l - summary.string_length_measured_mm);
    summary.string_length_spread_mm = kMadToSigma * UpperMedian(lengths);
  }
  summary.warnings = label_warnings;
  summary.warnings.insert(summary.warnings.end(),
                          summary.refinement.warnings.begin(),
                          summary.refinement.warnings.end());
  if (summary.string_length_frames == 0)
    summary.warnings.push_back(
        "no frame shows the nut and the bridge in two views with the result: the string length "
        "is not measured, so nothing checks the scale");
  for (const FromInstrumentCamera& c : summary.cameras)
    if (std::abs(c.focal_px / c.initial_focal_px - 1) > 0.03)
      summary.warnings.push_back(
          "camera " + c.name + "'s focal length moved by " +
          NumberText(std::round(1000 * (c.focal_px / c.initial_focal_px - 1)) / 10) +
          " % in the bundle adjustment: two views fix it poorly (docs/calibration.md); "
          "if it is known, give --focal-px with --fix-focal");
  if (options.focal_px == 0 && options.fov_deg == 0)
    summary.warnings.push_back("focal lengths started from a phone's default (" +
                               NumberText(kPhoneFovDeg) +
                               " deg); give --focal-px or --fov-deg when known");

  ARCO_RETURN_IF_ERROR(WriteCalibrationAndReport(options.output, format, report_file, summary));
  return summary;
}

}  // namespace arco::calibrate
