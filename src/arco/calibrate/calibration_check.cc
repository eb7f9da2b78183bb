#include "arco/calibrate/calibration_check.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "arco/calibration/calibration_file.h"
#include "arco/capture/label_views.h"
#include "arco/mocap/capture.h"
#include "arco/mocap/triangulate_point.h"
#include "arco/pipeline/capture_checks.h"
#include "arco/pipeline/result_folder.h"
#include "arco/util/file_io.h"
#include "arco/util/stats.h"

namespace arco::calibrate {

using pipeline::CheckCaptureCalibration;
using pipeline::kTriangulationStage;
using pipeline::ResultFolder;
using pipeline::ResultHeader;

Status CalibrationCheckOptions::Validate() const {
  if (!label_views.empty() && calibration.empty())
    return Status::Error("calibration: needed with labelled views");
  if (label_views.empty() && capture_dir.empty())
    return Status::Error("capture_dir: give a capture folder or labelled views");
  ARCO_RETURN_IF_ERROR(CheckInRange("min_score", min_score, Closed(0, 1)));
  ARCO_RETURN_IF_ERROR(CheckInRange("min_views", min_views, Closed(2, 1000)));
  ARCO_RETURN_IF_ERROR(CheckInRange("flag_ratio", flag_ratio, kCheckRatioRange));
  ARCO_RETURN_IF_ERROR(CheckInRange("min_flag_px", min_flag_px, kCheckMinFlagRangePx));
  ARCO_RETURN_IF_ERROR(CheckInRange("frame_step", frame_step, Closed(1, 1e6)));
  return Status::Ok();
}

Json CalibrationCheckSummary::ToJson() const {
  Json j;
  j["calibration"] = calibration;
  if (!result.empty()) j["result"] = result;
  j["frames"] = frames;
  j["rig_median_px"] = rig_median_px;
  j["threshold_px"] = threshold_px;
  j["cameras"] = Json::array();
  for (const CameraCheck& c : cameras) {
    Json ranges = Json::array();
    for (const auto& [first, last] : c.off_frames) ranges.push_back({first, last});
    j["cameras"].push_back({{"name", c.name},
                            {"residuals", c.residuals},
                            {"median_px", c.median_px},
                            {"p90_px", c.p90_px},
                            {"flagged", c.flagged},
                            {"off_frames", ranges}});
  }
  j["flagged"] = flagged;
  return j;
}

namespace {

// The medians, the threshold and the flags, from each camera's residuals.
Status Flag(const CalibrationCheckOptions& options,
            const std::vector<std::vector<double>>& residuals,
            CalibrationCheckSummary* summary) {
  std::vector<double> medians;
  for (size_t v = 0; v < residuals.size(); ++v) {
    CameraCheck& c = summary->cameras[v];
    c.residuals = static_cast<int64_t>(residuals[v].size());
    if (residuals[v].empty()) continue;
    c.median_px = Median(residuals[v]);
    c.p90_px = InterpolatedQuantile(residuals[v], 0.9);
    medians.push_back(c.median_px);
  }
  if (medians.empty())
    return Status::Error(
        (options.label_views.empty() ? options.capture_dir : options.label_views[0].second) +
        ": no keypoint is seen by " + std::to_string(options.min_views) +
        " cameras with a score of at least " + NumberText(options.min_score) +
        "; nothing to check");
  summary->rig_median_px = Median(medians);
  summary->threshold_px =
      std::max(options.min_flag_px, options.flag_ratio * summary->rig_median_px);
  for (CameraCheck& c : summary->cameras) {
    if (c.residuals == 0 || c.median_px <= summary->threshold_px) continue;
    c.flagged = true;
    summary->flagged.push_back(c.name);
  }
  return Status::Ok();
}

StatusOr<CalibrationCheckSummary> CheckLabelViews(const CalibrationCheckOptions& options) {
  capture::LabelViewsOptions labels;
  labels.calibration = options.calibration;
  labels.views = options.label_views;
  ARCO_ASSIGN_OR_RETURN(const Json triangulated, capture::TriangulateLabelViews(labels));
  CalibrationCheckSummary summary;
  summary.calibration = options.calibration;
  summary.frames = 1;
  std::vector<std::vector<double>> residuals(options.label_views.size());
  for (const auto& view : options.label_views) summary.cameras.emplace_back(view.first);
  for (const Json& point : triangulated["points"]) {
    if (static_cast<int>(point["inlier_views"].size()) < options.min_views) continue;
    for (size_t v = 0; v < options.label_views.size(); ++v) {
      const auto it = point["reprojection_px"].find(options.label_views[v].first);
      if (it != point["reprojection_px"].end() && it->is_number())
        residuals[v].push_back(it->template get<double>());
    }
  }
  ARCO_RETURN_IF_ERROR(Flag(options, residuals, &summary));
  return summary;
}

}  // namespace

StatusOr<CalibrationCheckSummary> CheckCalibration(const CalibrationCheckOptions& options,
                                                   Progress& progress) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  if (!options.label_views.empty()) return CheckLabelViews(options);
  // A result folder: its triangulated points against its capture's 2D keypoints.
  CalibrationCheckSummary summary;
  std::string capture_dir = options.capture_dir;
  std::optional<NpyArray<double>> result_points;
  ResultHeader header;
  if (FileExists(JoinPath(options.capture_dir, kResultManifestName))) {
    const ResultFolder result(options.capture_dir);
    ARCO_ASSIGN_OR_RETURN(header, result.ReadHeader());
    if (header.capture_dir.empty())
      return Status::Error(result.ManifestPath() + ": names no capture to check against");
    ARCO_ASSIGN_OR_RETURN(result_points, result.ReadPoints3d(kTriangulationStage));
    capture_dir = header.capture_dir;
    summary.result = options.capture_dir;
  }
  ARCO_ASSIGN_OR_RETURN(const CaptureManifest manifest, ReadCaptureManifest(capture_dir));
  if (manifest.keypoints2d.empty())
    return Status::Error(capture_dir + "/capture.json: no keypoints2d to check against");
  summary.calibration = options.calibration.empty()
                            ? ResolveCapturePath(capture_dir, manifest.calibration)
                            : options.calibration;
  // The capture's own calibration is checked as `arco run` checks it (messages name
  // capture.json's field); another one by its path.
  if (options.calibration.empty())
    ARCO_RETURN_IF_ERROR(CheckCaptureCalibration(capture_dir, manifest));
  ARCO_ASSIGN_OR_RETURN(const Calibration calibration,
                        calibration::LoadCalibration(summary.calibration));
  const Rig& rig = calibration.rig;
  if (result_points && header.units != rig.units)
    return Status::Error(options.capture_dir + "/result.json: points in '" + header.units +
                         "', the calibration " + summary.calibration + " in '" + rig.units + "'");
  ARCO_ASSIGN_OR_RETURN(
      const std::vector<int> view_to_camera,
      capture::MatchCaptureCameras(capture_dir, manifest, rig, summary.calibration));
  ARCO_RETURN_IF_ERROR(CheckCaptureKeypoints2d(capture_dir, manifest));
  ARCO_ASSIGN_OR_RETURN(const NpyArray<double> keypoints,
                        ReadCaptureKeypoints2d(capture_dir, manifest));
  const int64_t frames = keypoints.shape[0], views = keypoints.shape[1],
                points = keypoints.shape[2];

  TriangulationOptions triangulation;
  triangulation.min_score = options.min_score;
  const Triangulator triangulator(rig, triangulation);
  TriangulationScratch scratch;
  // residuals[view] over all frames; per_frame[view][frame] the frame's residuals.
  std::vector<std::vector<double>> residuals(views);
  std::vector<std::map<int64_t, std::vector<double>>> per_frame(views);
  std::vector<PointObservation> observations;
  std::vector<int> observation_view;
  progress.SetTotal((frames + options.frame_step - 1) / options.frame_step);
  for (int64_t f = 0; f < frames; f += options.frame_step) {
    ++summary.frames;
    for (int64_t p = 0; p < points; ++p) {
      observations.clear();
      observation_view.clear();
      for (int64_t v = 0; v < views; ++v) {
        const double x = keypoints.at(f, v, p, 0), y = keypoints.at(f, v, p, 1),
                     score = keypoints.at(f, v, p, 2);
        if (!std::isfinite(x) || !std::isfinite(y) || !(score >= options.min_score)) continue;
        observations.push_back({view_to_camera[v], Eigen::Vector2d(x, y), score});
        observation_view.push_back(static_cast<int>(v));
      }
      if (static_cast<int>(observations.size()) < options.min_views) continue;
      Eigen::Vector3d point_in_world;
      if (result_points) {
        // The result's point (triangulated when the result was made) at this frame.
        const int64_t r = manifest.frame_first + f - header.frame_first;
        if (r < 0 || r >= result_points->shape[0] || p >= result_points->shape[1]) continue;
        for (int d = 0; d < 3; ++d) point_in_world[d] = result_points->at(r, p, d);
        if (!point_in_world.allFinite()) continue;
      } else {
        const auto point = triangulator.Triangulate(observations, &scratch);
        if (!point || static_cast<int>(point->inlier_cameras.size()) < options.min_views) continue;
        point_in_world = point->point_in_world;
      }
      // Every view's residual, inlier or not: a moved camera is an outlier of the rest.
      for (size_t i = 0; i < observations.size(); ++i) {
        const double r = ReprojectionErrorPx(
            rig.cameras[observations[i].camera], point_in_world, observations[i].pixel);
        if (!std::isfinite(r)) continue;
        residuals[observation_view[i]].push_back(r);
        per_frame[observation_view[i]][manifest.frame_first + f].push_back(r);
      }
    }
    progress.Advance(1);
  }
  for (int64_t v = 0; v < views; ++v) summary.cameras.emplace_back(manifest.cameras[v].name);
  ARCO_RETURN_IF_ERROR(Flag(options, residuals, &summary));
  for (int64_t v = 0; v < views; ++v) {
    CameraCheck& c = summary.cameras[v];
    if (!c.flagged) continue;
    for (const auto& [frame, r] : per_frame[v]) {
      if (Median(r) <= summary.threshold_px) continue;
      if (!c.off_frames.empty() && c.off_frames.back().second + options.frame_step >= frame)
        c.off_frames.back().second = frame;
      else
        c.off_frames.push_back({frame, frame});
    }
  }
  return summary;
}

}  // namespace arco::calibrate
