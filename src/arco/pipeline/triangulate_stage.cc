#include "arco/pipeline/triangulate_stage.h"

#include "arco/calibration/calibration_file.h"
#include "arco/instrument/nominal_keypoints.h"
#include "arco/mocap/capture.h"
#include "arco/pipeline/capture_checks.h"
#include "arco/pipeline/result_folder.h"
#include "arco/util/file_io.h"

namespace arco::pipeline {

Status TriangulateStageOptions::Validate() const {
  if (capture_dir.empty()) return Status::Error("capture_dir is empty");
  if (result_dir.empty()) return Status::Error("result_dir is empty");
  ARCO_RETURN_IF_ERROR(one_view.Validate().WithContext("one_view"));
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
  const track::MonocularLiftOptions& v = o.one_view;
  j["one_view"] = {{"min_score", v.min_score},
                   {"min_instrument_points", v.min_instrument_points},
                   {"pnp_gate_px", v.pnp_gate_px},
                   {"body_behind_mm", v.body_behind_mm},
                   {"depth_window_frames", v.depth_window_frames},
                   {"end_pin_depth_window_frames", v.end_pin_depth_window_frames},
                   {"rotation_window_frames", v.rotation_window_frames},
                   {"min_ray_plane_cos", v.min_ray_plane_cos}};
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
  StatusOr<Calibration> calibration = calibration::LoadCalibration(calibration_path);
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

// The world's units per mm of a one-camera capture: any scale is consistent with one
// view (every point moves along its ray with it), so the calibration's own unit is kept
// when it says what it is, else the world is taken to be in mm.
double OneViewWorldUnitsPerMm(const std::string& units) {
  if (units == "m") return 1e-3;
  return 1.0;
}

// The instrument, its strings and the points lifted to them (monocular_lift.h).
StatusOr<track::MonocularScene> OneViewScene(const CaptureContext& capture) {
  const InstrumentModel& model = *capture.instrument;
  const std::vector<Eigen::Vector3d> nominal = NominalPoseKeypointsInInstrument(model);
  track::MonocularScene scene;
  for (int k : model.rigid_keypoints()) {
    const int column = capture.layout.Find(model.keypoint_names()[static_cast<size_t>(k)]);
    if (column < 0 || !nominal[static_cast<size_t>(k)].allFinite()) continue;
    scene.instrument_columns.push_back(column);
    scene.instrument_points_mm.push_back(nominal[static_cast<size_t>(k)]);
  }
  // The strings, evenly between the outer ones (within a millimetre of the model's
  // spacing); the instrument frame's z is to the front (instrument/strings.h).
  auto at = [&](const char* name) {
    return nominal[static_cast<size_t>(model.KeypointIndex(name))];
  };
  const int n = model.num_strings();
  for (int i = 0; i < n; ++i) {
    const double w = n == 1 ? 0.5 : static_cast<double>(i) / (n - 1);
    scene.strings_mm.emplace_back((1 - w) * at("nut_l") + w * at("nut_r"),
                                  (1 - w) * at("bridge_l") + w * at("bridge_r"));
  }
  scene.front = Eigen::Vector3d::UnitZ();
  scene.stands_on_end_pin =
      model.kind() == InstrumentKind::kCello || model.kind() == InstrumentKind::kDoubleBass;
  if (const std::vector<int>* g = capture.layout.Group("left_hand")) {
    scene.string_line_columns = *g;
    // The four fingers' tips (hand-21 order: 4 points per finger after the wrist).
    for (int tip : {8, 12, 16, 20}) scene.string_line_depth_columns.push_back((*g)[tip]);
  }
  if (const std::vector<int>* g = capture.layout.Group("bow")) scene.unlifted_columns = *g;
  return scene;
}

// Stage 1 of a one-camera capture: every keypoint lifted from its view
// (track/monocular_lift.h), in the shape of a triangulation (one view, its only inlier).
StatusOr<SequenceTriangulation> LiftOneViewCapture(const CaptureContext& capture,
                                                   const NpyArray<double>& keypoints2d,
                                                   const track::MonocularLiftOptions& options) {
  const double s = OneViewWorldUnitsPerMm(capture.calibration.rig.units);
  const std::vector<Camera> cameras = ViewCamerasInMm(capture, s);
  ARCO_ASSIGN_OR_RETURN(const track::MonocularScene scene, OneViewScene(capture));
  const std::string source = ResolveCapturePath(capture.capture_dir, capture.manifest.keypoints2d);
  StatusOr<track::MonocularLift> lift =
      track::LiftOneView(cameras.at(0), keypoints2d, scene, options);
  if (!lift.ok()) return lift.status().WithContext(source);
  if (lift->summary.frames_with_pose == 0)
    return Status::Error(source + ": no frame shows " +
                         std::to_string(options.min_instrument_points) + " of the " +
                         capture.manifest.instrument +
                         "'s points in a pose a PnP agrees with (one camera places everything "
                         "from the instrument's pose)");
  const int64_t frames = keypoints2d.shape[0], points = keypoints2d.shape[2];
  SequenceTriangulation out;
  out.points3d = std::move(lift->points3d_mm);
  for (double& x : out.points3d.data) x *= s;
  out.rms_reprojection_px.shape = {frames, points};
  out.num_inliers.shape = out.num_views.shape = {frames, points};
  out.inlier_mask.shape = {frames, points, 1};
  out.depth_source = std::move(lift->depth_source);
  out.depth_sigma_mm = std::move(lift->depth_sigma_mm);
  for (int64_t f = 0; f < frames; ++f) {
    for (int64_t p = 0; p < points; ++p) {
      const bool lifted = out.depth_source.at(f, p) != 0;
      // The instrument's points reproject with the PnP's residual; a point lifted along
      // its own ray reprojects exactly.
      const bool instrument =
          out.depth_source.at(f, p) == static_cast<uint8_t>(track::LiftDepth::kInstrumentPose);
      out.rms_reprojection_px.data.push_back(!lifted ? NAN
                                             : instrument
                                                 ? lift->pnp_rms_px.data[static_cast<size_t>(f)]
                                                 : 0.0f);
      out.num_inliers.data.push_back(lifted ? 1 : 0);
      out.num_views.data.push_back(std::isfinite(keypoints2d.at(f, 0, p, 0)) ? 1 : 0);
      out.inlier_mask.data.push_back(lifted ? 1 : 0);
    }
  }
  return out;
}

}  // namespace

StatusOr<TriangulateStageResult> RunTriangulateStage(const TriangulateStageOptions& o,
                                                     const CaptureContext& capture,
                                                     Progress& progress) {
  // Options validated and their filters checked against the capture by the caller
  // (RunCapture's preflight, OpenForTriangulation).
  const CaptureManifest& manifest = capture.manifest;
  const KeypointLayout& layout = capture.layout;
  std::vector<const std::vector<int>*> filter_groups;
  for (const auto& entry : o.filters) filter_groups.push_back(layout.Group(entry.first));
  ARCO_ASSIGN_OR_RETURN(const std::shared_ptr<const NpyArray<double>> keypoints2d,
                        ReadKeypoints2d(capture));
  TriangulateStageResult out;
  TriangulationRecord& record = out.record;
  record.inputs =
      SelectInputs(capture.inputs, {kManifestInput, kCalibrationInput, kKeypoints2dInput});
  progress.SetTotal(manifest.frame_count);
  const bool one_view = capture.view_to_camera.size() == 1;
  SequenceTriangulation& raw = out.raw;
  if (one_view) {
    ARCO_ASSIGN_OR_RETURN(raw, LiftOneViewCapture(capture, *keypoints2d, o.one_view));
    progress.Advance(manifest.frame_count);
  } else {
    ARCO_ASSIGN_OR_RETURN(
        raw,
        TriangulateSequence(capture.calibration.rig,
                            capture.view_to_camera,
                            *keypoints2d,
                            o.triangulation,
                            &progress,
                            ResolveCapturePath(capture.capture_dir, manifest.keypoints2d)));
  }
  NpyArray<double>& filtered = out.points3d;
  filtered = raw.points3d;
  for (size_t i = 0; i < filter_groups.size(); ++i) {
    FilterPoints(o.filters[i].second, manifest.fps, *filter_groups[i], &filtered);
  }
  // The result names the capture as the options do (the run's capture_dir is the
  // capture's).
  record.capture_dir = o.capture_dir;
  if (one_view) {
    record.one_view_camera_centre =
        capture.calibration.rig.cameras.at(static_cast<size_t>(capture.view_to_camera.at(0)))
            .CenterInWorld();
  }
  record.units = capture.calibration.rig.units;
  record.summary = Summarize(raw);
  record.options = ToJson(o);
  TriangulateStageSummary& summary = out.summary;
  summary.triangulation = record.summary;
  summary.units = record.units;
  summary.views = static_cast<int64_t>(capture.view_to_camera.size());
  summary.keypoints = layout.size();
  return out;
}

Status WriteTriangulation(const ResultFolder& result,
                          const CaptureContext& capture,
                          TriangulateStageResult* stage) {
  ARCO_ASSIGN_OR_RETURN(
      stage->summary.removed_stages,
      result.WriteTriangulation(
          capture.manifest, capture.layout, stage->raw, stage->points3d, stage->record));
  stage->raw = {};
  return Status::Ok();
}

StatusOr<TriangulateStageSummary> RunTriangulateStage(const TriangulateStageOptions& o,
                                                      Progress& progress) {
  ARCO_RETURN_IF_ERROR(o.Validate());
  ARCO_RETURN_IF_ERROR(ResultFolder(o.result_dir).CheckWritable());  // before the work
  ARCO_ASSIGN_OR_RETURN(const CaptureContext capture, OpenForTriangulation(o));
  ARCO_ASSIGN_OR_RETURN(TriangulateStageResult out, RunTriangulateStage(o, capture, progress));
  ARCO_RETURN_IF_ERROR(WriteTriangulation(ResultFolder(o.result_dir), capture, &out));
  return std::move(out.summary);
}

}  // namespace arco::pipeline
