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

StatusOr<TriangulateStageSummary> RunTriangulateStage(
    const TriangulateStageOptions& o,
    Progress& progress,
    std::shared_ptr<const NpyArray<double>> keypoints2d) {
  ARCO_RETURN_IF_ERROR(o.Validate());
  ARCO_RETURN_IF_ERROR(ResultFolder(o.result_dir).CheckWritable());  // before the work
  ARCO_ASSIGN_OR_RETURN(CaptureManifest manifest, ReadCaptureManifest(o.capture_dir));
  const std::string manifest_path = JoinPath(o.capture_dir, kCaptureManifestName);
  ARCO_ASSIGN_OR_RETURN(KeypointLayout layout, [&]() -> StatusOr<KeypointLayout> {
    ARCO_RETURN_IF_ERROR(CheckCaptureHasKeypoints2d(o.capture_dir, manifest));
    auto l = manifest.Layout();
    if (!l.ok()) return l.status().WithContext(manifest_path);
    return l;
  }());
  // Filters refer to groups of the layout; checked before any work (pipeline/capture_checks.h).
  ARCO_RETURN_IF_ERROR(CheckTriangulationFilters(o, layout, manifest.fps, manifest_path));
  std::vector<const std::vector<int>*> filter_groups;
  for (const auto& entry : o.filters) filter_groups.push_back(layout.Group(entry.first));
  const std::string calibration_path = ResolveCapturePath(o.capture_dir, manifest.calibration);
  StatusOr<Calibration> calibration = LoadCalibration(calibration_path);
  if (!calibration.ok()) return calibration.status().WithContext(manifest_path + ": calibration");
  ARCO_ASSIGN_OR_RETURN(
      const std::vector<int> view_to_camera,
      MatchCaptureCameras(o.capture_dir, manifest, calibration->rig, calibration_path));
  if (!keypoints2d) {
    ARCO_ASSIGN_OR_RETURN(NpyArray<double> read, ReadCaptureKeypoints2d(o.capture_dir, manifest));
    keypoints2d = std::make_shared<const NpyArray<double>>(std::move(read));
  }
  const NpyArray<double>& keypoints = *keypoints2d;
  TriangulationRecord record;
  ARCO_ASSIGN_OR_RETURN(
      record.inputs,
      FingerprintCaptureInputs(
          o.capture_dir, manifest, {kManifestInput, kCalibrationInput, kKeypoints2dInput}));
  progress.SetTotal(manifest.frame_count);
  ARCO_ASSIGN_OR_RETURN(
      SequenceTriangulation raw,
      TriangulateSequence(calibration->rig,
                          view_to_camera,
                          keypoints,
                          o.triangulation,
                          &progress,
                          ResolveCapturePath(o.capture_dir, manifest.keypoints2d)));
  NpyArray<double> filtered = raw.points3d;
  for (size_t i = 0; i < filter_groups.size(); ++i) {
    FilterPoints(o.filters[i].second, manifest.fps, *filter_groups[i], &filtered);
  }
  record.capture_dir = o.capture_dir;
  record.units = calibration->rig.units;
  record.summary = Summarize(raw);
  record.options = ToJson(o);
  TriangulateStageSummary summary;
  ARCO_ASSIGN_OR_RETURN(
      summary.removed_stages,
      ResultFolder(o.result_dir).WriteTriangulation(manifest, layout, raw, filtered, record));
  summary.triangulation = record.summary;
  summary.units = record.units;
  summary.views = static_cast<int64_t>(view_to_camera.size());
  summary.keypoints = layout.size();
  return summary;
}

}  // namespace arco::pipeline
