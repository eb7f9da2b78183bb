#include "arco/pipeline/triangulate_stage.h"

#include "arco/calibration/calibration_file.h"
#include "arco/mocap/capture.h"
#include "arco/pipeline/capture_checks.h"
#include "arco/pipeline/result_folder.h"
#include "arco/util/file_io.h"

namespace arco::pipeline {

Status TriangulateStageOptions::Validate() const {
  if (capture_dir.empty()) return Status::Error("capture_dir is empty");
  if (result_dir.empty()) return Status::Error("result_dir is empty");
  return triangulation.Validate();
}

Json ToJson(const TriangulateStageOptions& o) {
  Json filters = Json::array();
  for (const auto& [group, filter] : o.filters) {
    filters.push_back({{"group", group},
                       {"filter", FilterSpecToString(filter)},
                       {"max_gap_frames", filter.max_gap_frames}});
  }
  Json j = ToJson(o.triangulation.point);
  j["filters"] = filters;
  return j;
}

namespace {

// The capture as `arco triangulate` needs it, checked in the order the stage always has:
// the manifest, its keypoints and layout, the filters, the calibration, the keypoints'
// data, the fingerprints.
StatusOr<CaptureContext> OpenForTriangulation(const TriangulateStageOptions& o) {
  CaptureContext capture;
  capture.capture_dir = o.capture_dir;
  ARCO_ASSIGN_OR_RETURN(capture.manifest, ReadCaptureManifest(o.capture_dir));
  const CaptureManifest& manifest = capture.manifest;
  const std::string manifest_path = CaptureManifestPath(o.capture_dir);
  ARCO_ASSIGN_OR_RETURN(capture.layout, [&]() -> StatusOr<KeypointLayout> {
    ARCO_RETURN_IF_ERROR(CheckCaptureHasKeypoints2d(o.capture_dir, manifest));
    auto l = manifest.Layout();
    if (!l.ok()) return l.status().WithContext(manifest_path);
    return l;
  }());
  // Filters refer to groups of the layout; checked before any work (pipeline/capture_checks.h).
  ARCO_RETURN_IF_ERROR(CheckTriangulationFilters(o, capture.layout, manifest.fps, manifest_path));
  const std::string calibration_path = ResolveCapturePath(o.capture_dir, manifest.calibration);
  StatusOr<Calibration> calibration = LoadCalibration(calibration_path);
  if (!calibration.ok()) return calibration.status().WithContext(manifest_path + ": calibration");
  ARCO_ASSIGN_OR_RETURN(
      capture.view_to_camera,
      capture::MatchCaptureCameras(o.capture_dir, manifest, calibration->rig, calibration_path));
  capture.calibration = std::move(calibration).value();
  ARCO_ASSIGN_OR_RETURN(capture.keypoints2d, ReadKeypoints2d(capture));
  ARCO_ASSIGN_OR_RETURN(
      capture.inputs,
      FingerprintCaptureInputs(
          o.capture_dir, manifest, {kManifestInput, kCalibrationInput, kKeypoints2dInput}));
  return capture;
}

}  // namespace

StatusOr<TriangulateStageResult> RunTriangulateStage(const TriangulateStageOptions& o,
                                                     const CaptureContext& capture,
                                                     Progress& progress) {
  return RunTriangulateStage(o, capture, ResultFolder(o.result_dir), progress);
}

StatusOr<TriangulateStageResult> RunTriangulateStage(const TriangulateStageOptions& o,
                                                     const CaptureContext& capture,
                                                     const ResultFolder& result,
                                                     Progress& progress) {
  ARCO_RETURN_IF_ERROR(o.Validate());
  result.RequireDir(o.result_dir);
  ARCO_RETURN_IF_ERROR(result.CheckWritable());  // before the work
  const CaptureManifest& manifest = capture.manifest;
  const KeypointLayout& layout = capture.layout;
  const std::string manifest_path = CaptureManifestPath(capture.capture_dir);
  ARCO_RETURN_IF_ERROR(CheckTriangulationFilters(o, layout, manifest.fps, manifest_path));
  std::vector<const std::vector<int>*> filter_groups;
  for (const auto& entry : o.filters) filter_groups.push_back(layout.Group(entry.first));
  ARCO_ASSIGN_OR_RETURN(const std::shared_ptr<const NpyArray<double>> keypoints2d,
                        ReadKeypoints2d(capture));
  TriangulationRecord record;
  record.inputs =
      SelectInputs(capture.inputs, {kManifestInput, kCalibrationInput, kKeypoints2dInput});
  progress.SetTotal(manifest.frame_count);
  ARCO_ASSIGN_OR_RETURN(
      SequenceTriangulation raw,
      TriangulateSequence(capture.calibration.rig,
                          capture.view_to_camera,
                          *keypoints2d,
                          o.triangulation,
                          &progress,
                          ResolveCapturePath(capture.capture_dir, manifest.keypoints2d)));
  TriangulateStageResult out;
  NpyArray<double>& filtered = out.points3d;
  filtered = raw.points3d;
  for (size_t i = 0; i < filter_groups.size(); ++i) {
    FilterPoints(o.filters[i].second, manifest.fps, *filter_groups[i], &filtered);
  }
  // The result names the capture as the options do (the run's capture_dir is the
  // capture's).
  record.capture_dir = o.capture_dir;
  record.units = capture.calibration.rig.units;
  record.summary = Summarize(raw);
  record.options = ToJson(o);
  TriangulateStageSummary& summary = out.summary;
  ARCO_ASSIGN_OR_RETURN(summary.removed_stages,
                        result.WriteTriangulation(manifest, layout, raw, filtered, record));
  summary.triangulation = record.summary;
  summary.units = record.units;
  summary.views = static_cast<int64_t>(capture.view_to_camera.size());
  summary.keypoints = layout.size();
  return out;
}

StatusOr<TriangulateStageSummary> RunTriangulateStage(const TriangulateStageOptions& o,
                                                      Progress& progress) {
  ARCO_RETURN_IF_ERROR(o.Validate());
  ARCO_RETURN_IF_ERROR(ResultFolder(o.result_dir).CheckWritable());  // before the work
  ARCO_ASSIGN_OR_RETURN(const CaptureContext capture, OpenForTriangulation(o));
  ARCO_ASSIGN_OR_RETURN(TriangulateStageResult out, RunTriangulateStage(o, capture, progress));
  return std::move(out.summary);
}

}  // namespace arco::pipeline
