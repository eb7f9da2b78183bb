#include "arco/calibrate/calibration_refine.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "arco/calibration/bundle_adjustment.h"
#include "arco/calibration/calibration_file.h"
#include "arco/calibration/pose_parameters.h"
#include "arco/geometry/rotation.h"
#include "arco/instrument/instrument_model.h"
#include "arco/instrument/template_fit.h"
#include "arco/mocap/capture.h"
#include "arco/mocap/triangulate_point.h"
#include "arco/pipeline/capture_checks.h"
#include "arco/pipeline/result_folder.h"  // pipeline::kNaN
#include "arco/registry/keypoint_layout.h"
#include "arco/util/output_set.h"

namespace arco::calibrate {

using pipeline::CaptureContext;
using pipeline::kNaN;
using pipeline::LoadCaptureCalibration;
using pipeline::LoadCaptureKeypoints2d;
namespace {

// Every camera must keep this many detections, or its pose is left to a handful of points.
constexpr int64_t kMinCameraObservations = 30;
constexpr int64_t kMinPoints = 30;

using calibration::BundleObservation;
using calibration::BundleTrack;
using calibration::Rms;

}  // namespace

StatusOr<CalibrationFormat> CalibrationOutputFormat(const std::string& path) {
  const std::string extension = std::filesystem::path(path).extension().string();
  if (extension == ".yaml" || extension == ".yml") return CalibrationFormat::kOpenCvYaml;
  if (extension == ".xml") return CalibrationFormat::kOpenCvXml;
  if (extension == ".json") return CalibrationFormat::kArcoJson;
  return Status::Error(path +
                       ": unknown calibration extension (.json arco JSON, .yaml/.yml OpenCV "
                       "YAML, .xml OpenCV XML)");
}

std::string RefineReportPath(const std::string& output) {
  std::filesystem::path report_path(output);
  report_path.replace_extension();
  return report_path.string() + ".report.json";
}

Status CalibrationRefineOptions::Validate() const {
  if (capture_dir.empty()) return Status::Error("capture_dir: no capture folder given");
  if (write && output.empty()) return Status::Error("output: no calibration file given");
  ARCO_RETURN_IF_ERROR(CheckInRange("min_score", min_score, Closed(0, 1)));
  ARCO_RETURN_IF_ERROR(CheckInRange("min_views", min_views, Closed(2, 1000)));
  ARCO_RETURN_IF_ERROR(CheckInRange("max_frames", max_frames, kRefineMaxFramesRange));
  ARCO_RETURN_IF_ERROR(CheckInRange("initial_gate_px", initial_gate_px, kRefineGateRangePx));
  ARCO_RETURN_IF_ERROR(CheckInRange("gate_px", gate_px, kRefineGateRangePx));
  ARCO_RETURN_IF_ERROR(CheckInRange("loss_scale_px", loss_scale_px, kRefineLossRangePx));
  ARCO_RETURN_IF_ERROR(CheckInRange("max_iterations", max_iterations, kRefineIterationsRange));
  return Status::Ok();
}

Json CalibrationRefineSummary::ToJson() const {
  Json j;
  j["calibration"] = calibration;
  j["output"] = output;
  j["units"] = units;
  j["reference_camera"] = reference_camera;
  j["frames"] = frames;
  j["points"] = points;
  j["instrument"] = {{"frames", instrument_frames},
                     {"points", instrument_points},
                     {"string_length_mm", string_length_mm},
                     {"string_length_before_mm", string_length_before_mm}};
  j["rms_before_px"] = rms_before_px;
  j["rms_after_px"] = rms_after_px;
  j["cameras"] = Json::array();
  for (const CameraRefinement& c : cameras)
    j["cameras"].push_back({{"name", c.name},
                            {"reference", c.reference},
                            {"observations", c.observations},
                            {"rms_before_px", c.rms_before_px},
                            {"rms_after_px", c.rms_after_px},
                            {"rotation_change_deg", c.rotation_change_deg},
                            {"centre_change_mm", c.centre_change_mm},
                            {"focal_change_rel", c.focal_change_rel}});
  j["passes"] = Json::array();
  for (const Pass& p : passes)
    j["passes"].push_back({{"termination", p.termination},
                           {"iterations", p.iterations},
                           {"initial_cost", p.initial_cost},
                           {"final_cost", p.final_cost},
                           {"residual_blocks", p.residual_blocks}});  // no time: same bytes
  j["warnings"] = warnings;
  return j;
}

StatusOr<CalibrationRefineSummary> RefineCalibration(const CalibrationRefineOptions& options,
                                                     Progress& progress) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  CalibrationFormat format = CalibrationFormat::kArcoJson;
  std::string report_file;
  if (options.write) {
    ARCO_ASSIGN_OR_RETURN(format, CalibrationOutputFormat(options.output));
    report_file = RefineReportPath(options.output);
    for (const std::string& path : {options.output, report_file}) {
      ARCO_RETURN_IF_ERROR(CheckOutputFile(path));
      if (!options.overwrite && std::filesystem::exists(path))
        return Status::Error(path + ": exists; give --overwrite to replace it");
    }
  }

  // The capture is read through its context's readers (capture_context.h), each file once.
  CaptureContext capture;
  capture.capture_dir = options.capture_dir;
  if (options.capture_manifest) {
    capture.manifest = *options.capture_manifest;
  } else {
    ARCO_ASSIGN_OR_RETURN(capture.manifest, ReadCaptureManifest(options.capture_dir));
  }
  const CaptureManifest& manifest = capture.manifest;
  if (manifest.keypoints2d.empty())
    return Status::Error(options.capture_dir + "/capture.json: no keypoints2d to refine with");
  CalibrationRefineSummary summary;
  summary.calibration = options.calibration.empty() && !options.input_rig
                            ? ResolveCapturePath(options.capture_dir, manifest.calibration)
                            : options.calibration;
  summary.output = options.output;
  Calibration calibration;
  if (options.input_rig) {
    calibration.rig = *options.input_rig;
  } else if (options.calibration.empty()) {
    // The capture's own: checked and parsed from one read.
    ARCO_RETURN_IF_ERROR(LoadCaptureCalibration(&capture));
    calibration = capture.calibration;
  } else {
    ARCO_ASSIGN_OR_RETURN(calibration, calibration::LoadCalibration(summary.calibration));
  }
  const Rig& input = calibration.rig;
  summary.units = input.units;
  ARCO_ASSIGN_OR_RETURN(
      const std::vector<int> view_to_camera,
      capture::MatchCaptureCameras(options.capture_dir, manifest, input, summary.calibration));
  const int num_cameras = static_cast<int>(input.cameras.size());
  if (view_to_camera.size() < 2)
    return Status::Error(options.capture_dir +
                         ": refining a calibration needs at least two "
                         "cameras, the capture has " +
                         std::to_string(view_to_camera.size()));
  int reference = view_to_camera[0];
  if (!options.reference_camera.empty()) {
    reference = -1;
    for (int c : view_to_camera)
      if (input.cameras[c].name == options.reference_camera) reference = c;
    if (reference < 0)
      return Status::Error("reference camera '" + options.reference_camera +
                           "' is not one of the capture's cameras");
  }
  summary.reference_camera = input.cameras[reference].name;

  // The instrument: its rigid keypoints (layout columns) and the scale.
  if (manifest.instrument.empty() || manifest.instrument == "none")
    return Status::Error(options.capture_dir +
                         "/capture.json: no instrument; refine takes the rig's metric scale "
                         "from the instrument's string length");
  ARCO_ASSIGN_OR_RETURN(const InstrumentModel model, InstrumentModel::Create(manifest.instrument));
  const KeypointLayout* layout = FindKeypointLayout(manifest.layout);
  if (layout == nullptr)
    return Status::Error(options.capture_dir + "/capture.json: unknown layout '" + manifest.layout +
                         "'");
  const std::vector<std::string>& names = model.keypoint_names();
  const int num_k = static_cast<int>(names.size());
  std::vector<int> rigid_of_point(layout->size(), -1);
  for (int k = 0; k < num_k; ++k) {
    if (names[k] == "frog" || names[k] == "tip") continue;  // the bow: free points
    const int column = layout->Find(names[k]);
    if (column >= 0) rigid_of_point[column] = k;
  }
  const int nut_l = model.KeypointIndex("nut_l"), nut_r = model.KeypointIndex("nut_r"),
            bridge_l = model.KeypointIndex("bridge_l"), bridge_r = model.KeypointIndex("bridge_r");
  InstrumentFitOptions fit_options;
  double units_per_mm = 0;
  if (input.units == "mm") {
    fit_options.scale = InstrumentFitOptions::Scale::kWorldIsMillimetres;
    units_per_mm = 1;
  } else if (input.units == "m") {
    fit_options.scale = InstrumentFitOptions::Scale::kGiven;
    fit_options.world_units_per_mm = units_per_mm = 1e-3;
  }

  if (options.input_keypoints == nullptr) ARCO_RETURN_IF_ERROR(LoadCaptureKeypoints2d(&capture));
  const NpyArray<double>& keypoints =
      options.input_keypoints != nullptr ? *options.input_keypoints : *capture.keypoints2d;
  const int64_t frames = keypoints.shape[0], views = keypoints.shape[1],
                points = keypoints.shape[2];
  if (points != layout->size())
    return Status::Error(ResolveCapturePath(options.capture_dir, manifest.keypoints2d) + ": " +
                         std::to_string(points) + " keypoints per view, layout " + manifest.layout +
                         " has " + std::to_string(layout->size()));
  // Frames evenly spread over the capture.
  std::vector<int64_t> selected;
  const int64_t used_frames = std::min<int64_t>(frames, options.max_frames);
  for (int64_t i = 0; i < used_frames; ++i)
    selected.push_back(used_frames == 1 ? 0 : i * (frames - 1) / (used_frames - 1));
  const int num_frames = static_cast<int>(selected.size());
  summary.frames = num_frames;

  Rig rig = input;
  calibration::RigidBody body;
  body.points.assign(num_k, Eigen::Vector3d::Constant(kNaN));
  body.rotation.assign(num_frames, Eigen::Matrix3d::Identity());
  body.translation.assign(num_frames, Eigen::Vector3d::Zero());
  body.valid.assign(num_frames, 0);
  std::vector<BundleTrack> tracks;
  // Progress counts passes (no stage line: an error is then the command's only line).
  progress.SetTotal(3);

  struct PassPlan {
    double gate_px, loss_px;
  };
  const PassPlan plan[3] = {
      {options.initial_gate_px, std::max(8 * options.loss_scale_px, 16.0)},
      {std::max(3 * options.gate_px, options.gate_px), 4 * options.loss_scale_px},
      {options.gate_px, options.loss_scale_px}};
  // Enough to go on: the rig enough points, every camera enough detections of them.
  auto enough = [&]() -> Status {
    std::vector<int64_t> per_camera(num_cameras, 0);
    for (const BundleTrack& t : tracks)
      for (const BundleObservation& o : t.observations) ++per_camera[o.camera];
    if (static_cast<int64_t>(tracks.size()) < kMinPoints)
      return Status::Error(ResolveCapturePath(options.capture_dir, manifest.keypoints2d) +
                           ": only " + std::to_string(tracks.size()) + " keypoints are seen by " +
                           std::to_string(options.min_views) +
                           " cameras with a score of at least " + NumberText(options.min_score) +
                           " (" + std::to_string(kMinPoints) + " needed to refine the rig)");
    for (int c : view_to_camera)
      if (per_camera[c] < kMinCameraObservations)
        return Status::Error(ResolveCapturePath(options.capture_dir, manifest.keypoints2d) +
                             ": camera " + input.cameras[c].name + " has only " +
                             std::to_string(per_camera[c]) + " detections of keypoints that " +
                             std::to_string(options.min_views) + " cameras agree on (" +
                             std::to_string(kMinCameraObservations) +
                             " needed to refine its pose)");

    return Status::Ok();
  };
  for (int pass = 0; pass < 3; ++pass) {
    // 1. Tracks: points triangulated with the current rig, their agreeing views.
    TriangulationOptions triangulation;
    triangulation.min_score = options.min_score;
    triangulation.max_reprojection_px = plan[pass].gate_px;
    const Triangulator triangulator(rig, triangulation);
    TriangulationScratch scratch;
    tracks.clear();
    std::vector<PointObservation> observations;
    for (int f = 0; f < num_frames; ++f)
      for (int64_t p = 0; p < points; ++p) {
        observations.clear();
        for (int64_t v = 0; v < views; ++v) {
          const double x = keypoints.at(selected[f], v, p, 0),
                       y = keypoints.at(selected[f], v, p, 1),
                       score = keypoints.at(selected[f], v, p, 2);
          if (!std::isfinite(x) || !std::isfinite(y) || !(score >= options.min_score)) continue;
          observations.push_back({view_to_camera[v], Eigen::Vector2d(x, y), score});
        }
        if (static_cast<int>(observations.size()) < options.min_views) continue;
        const auto point = triangulator.Triangulate(observations, &scratch);
        if (!point || static_cast<int>(point->inlier_cameras.size()) < options.min_views) continue;
        BundleTrack track;
        track.frame = f;
        track.point = static_cast<int>(p);
        track.rigid = rigid_of_point[p];
        track.point_in_world = point->point_in_world;
        for (const PointObservation& o : observations)
          if (std::binary_search(
                  point->inlier_cameras.begin(), point->inlier_cameras.end(), o.camera))
            track.observations.push_back({o.camera, o.pixel});
        tracks.push_back(std::move(track));
      }

    ARCO_RETURN_IF_ERROR(enough());

    // 2. The rigid instrument: fitted to the first pass's points, then carried over.
    if (pass == 0) {
      std::vector<Eigen::Matrix3Xd> instrument_points(num_frames,
                                                      Eigen::Matrix3Xd::Constant(3, num_k, kNaN));
      std::vector<FrontHint> hints(num_frames);
      std::vector<Eigen::Vector3d> shoulders(2 * num_frames, Eigen::Vector3d::Constant(kNaN));
      for (const BundleTrack& t : tracks) {
        if (t.rigid >= 0) instrument_points[t.frame].col(t.rigid) = t.point_in_world;
        if (t.point == wholebody::kLeftShoulder) shoulders[2 * t.frame] = t.point_in_world;
        if (t.point == wholebody::kRightShoulder) shoulders[2 * t.frame + 1] = t.point_in_world;
      }
      for (int f = 0; f < num_frames; ++f)
        hints[f].value = 0.5 * (shoulders[2 * f] + shoulders[2 * f + 1]);
      StatusOr<InstrumentFit> fit = FitInstrument(model, instrument_points, hints, fit_options);
      if (!fit.ok())
        return Status::Error(options.capture_dir +
                             ": the instrument's keypoints give no rigid "
                             "body to take the scale from (" +
                             fit.status().message() + ")");
      const double s = fit->instrument.world_units_per_mm;
      if (units_per_mm == 0) units_per_mm = s;
      for (int k = 0; k < num_k; ++k)
        body.points[k] = s * fit->instrument.keypoints_in_instrument[k];
      for (int f = 0; f < num_frames; ++f) {
        const InstrumentFramePose& pose = fit->frames[f];
        if (pose.status != FrameFitStatus::kOk) continue;
        body.valid[f] = 1;
        body.rotation[f] = pose.world_from_instrument.rotation;
        body.translation[f] = pose.world_from_instrument.translation;
      }
      for (int k : {nut_l, nut_r, bridge_l, bridge_r})
        if (k < 0 || !body.points[k].allFinite())
          return Status::Error(options.capture_dir +
                               ": the instrument's nut and bridge points are not seen well "
                               "enough to give the scale");
      summary.string_length_mm = model.string_length_mm();
      summary.string_length_before_mm = (0.5 * (body.points[nut_l] + body.points[nut_r]) -
                                         0.5 * (body.points[bridge_l] + body.points[bridge_r]))
                                            .norm() /
                                        units_per_mm;
    }
    // Rigid points only where the body has a pose and the template the point.
    tracks.erase(std::remove_if(tracks.begin(),
                                tracks.end(),
                                [&](const BundleTrack& t) {
                                  return t.rigid >= 0 && (!body.valid[t.frame] ||
                                                          !body.points[t.rigid].allFinite());
                                }),
                 tracks.end());
    // A frame's pose needs three of its points (two leave a rotation free).
    std::vector<int> rigid_in_frame(num_frames, 0);
    for (const BundleTrack& t : tracks) rigid_in_frame[t.frame] += t.rigid >= 0;
    tracks.erase(std::remove_if(tracks.begin(),
                                tracks.end(),
                                [&](const BundleTrack& t) {
                                  return t.rigid >= 0 && rigid_in_frame[t.frame] < 3;
                                }),
                 tracks.end());
    for (int f = 0; f < num_frames; ++f)
      if (rigid_in_frame[f] < 3) body.valid[f] = 0;
    ARCO_RETURN_IF_ERROR(enough());

    // 3. The bundle adjustment: the rig, the instrument and the free points.
    calibration::RigAdjustmentOptions adjustment;
    adjustment.reference_camera = reference;
    adjustment.cameras = view_to_camera;
    adjustment.refine_focal = options.refine_focal;
    // Cauchy while gross errors may remain (pass 1); Huber once the gate has removed them:
    // Cauchy's down-weighting near the noise level made the last pass's reduced system
    // indefinite (failed Cholesky steps, 70 iterations instead of a few).
    adjustment.loss =
        pass == 0 ? calibration::BundleLoss::kCauchy : calibration::BundleLoss::kHuber;
    adjustment.loss_scale_px = plan[pass].loss_px;
    adjustment.max_iterations = options.max_iterations;
    // The string length holds the scale; the weight only conditions the problem.
    adjustment.scale = {nut_l,
                        nut_r,
                        bridge_l,
                        bridge_r,
                        model.string_length_mm() * units_per_mm,
                        10.0 / units_per_mm};
    ARCO_ASSIGN_OR_RETURN(const calibration::BundleAdjustmentSummary solved,
                          calibration::AdjustRig(adjustment, tracks, &rig, &body));
    CalibrationRefineSummary::Pass report;
    report.termination = solved.termination;
    report.iterations = solved.iterations;
    report.initial_cost = solved.initial_cost;
    report.final_cost = solved.final_cost;
    report.residual_blocks = solved.residual_blocks;
    report.time_s = solved.time_s;
    summary.passes.push_back(report);
    progress.Advance(1);
  }

  // The report: per camera, the last pass's detections reprojected from points
  // triangulated with the input and with the refined calibration (same views).
  TriangulationOptions wide;
  wide.max_reprojection_px = 1e6;
  wide.min_score = 0;
  const Triangulator before(input, wide), after(rig, wide);
  std::vector<std::vector<double>> errors_before(num_cameras), errors_after(num_cameras);
  std::vector<PointObservation> observations;
  for (const BundleTrack& t : tracks) {
    if (t.rigid < 0) ++summary.points;
    observations.clear();
    for (const BundleObservation& o : t.observations)
      observations.push_back({o.camera, o.pixel, 1.0});
    for (const auto& [triangulator, errors] :
         {std::make_pair(&before, &errors_before), std::make_pair(&after, &errors_after)}) {
      const auto point = triangulator->Triangulate(observations);
      if (!point) continue;
      for (const BundleObservation& o : t.observations) {
        const double e = ReprojectionErrorPx(
            triangulator->rig().cameras[o.camera], point->point_in_world, o.pixel);
        if (std::isfinite(e)) (*errors)[o.camera].push_back(e);
      }
    }
  }
  for (int f = 0; f < num_frames; ++f) summary.instrument_frames += body.valid[f];
  for (int k = 0; k < num_k; ++k) summary.instrument_points += body.points[k].allFinite();
  std::vector<double> all_before, all_after;
  for (int c : view_to_camera) {
    CameraRefinement r;
    const Camera &a = input.cameras[c], &b = rig.cameras[c];
    r.name = a.name;
    r.reference = c == reference;
    r.observations = static_cast<int64_t>(errors_after[c].size());
    r.rms_before_px = Rms(errors_before[c]);
    r.rms_after_px = Rms(errors_after[c]);
    r.rotation_change_deg =
        RotationAngleBetween(a.cam_from_world.rotation, b.cam_from_world.rotation) * 180 / M_PI;
    r.centre_change_mm = (a.CenterInWorld() - b.CenterInWorld()).norm() / units_per_mm;
    r.focal_change_rel = b.fx / a.fx - 1;
    summary.cameras.push_back(r);
    all_before.insert(all_before.end(), errors_before[c].begin(), errors_before[c].end());
    all_after.insert(all_after.end(), errors_after[c].begin(), errors_after[c].end());
  }
  summary.rms_before_px = Rms(all_before);
  summary.rms_after_px = Rms(all_after);
  for (const CalibrationRefineSummary::Pass& p : summary.passes)
    if (p.termination != "CONVERGENCE")
      summary.warnings.push_back("a bundle adjustment pass ended with " + p.termination +
                                 " after " + std::to_string(p.iterations) + " iterations");
  summary.rig = rig;
  if (!options.write) return summary;

  OutputSet outputs;
  ARCO_ASSIGN_OR_RETURN(const std::string calibration_tmp, outputs.AddFile(options.output));
  ARCO_ASSIGN_OR_RETURN(const std::string report_tmp, outputs.AddFile(report_file));
  ARCO_RETURN_IF_ERROR(calibration::SaveCalibration(calibration_tmp, rig, format));
  {
    std::ofstream out(report_tmp);
    out << summary.ToJson().dump(2) << "\n";
    if (!out) return Status::Error(report_file + ": cannot write");
  }
  ARCO_RETURN_IF_ERROR(outputs.Commit());
  return summary;
}

}  // namespace arco::calibrate
