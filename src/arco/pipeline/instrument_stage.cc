#include "arco/pipeline/instrument_stage.h"

#include <limits>
#include <vector>

#include "arco/geometry/alignment.h"
#include "arco/instrument/nominal_keypoints.h"
#include "arco/pipeline/result_folder.h"
#include "arco/registry/keypoint_layout.h"

namespace arco::pipeline {
namespace {

constexpr int kLeftShoulder = wholebody::kLeftShoulder;
constexpr int kRightShoulder = wholebody::kRightShoulder;

}  // namespace

Status InstrumentStageOptions::Validate() const {
  if (result_dir.empty()) return Status::Error("result_dir is empty");
  if (num_threads < 0) return Status::Error("num_threads must be >= 0");
  ARCO_RETURN_IF_ERROR(fit.Validate().WithContext("fit"));
  for (double c : smoothing_candidates_frames) {
    if (!(c > 0 && c <= 300))
      return Status::Error("smoothing_candidates_frames must each be in (0, 300]");
  }
  return smoothing.Validate().WithContext("smoothing");
}

Json ToJson(const InstrumentStageOptions& o) {
  const InstrumentFitOptions& f = o.fit;
  const char* scale = f.scale == InstrumentFitOptions::Scale::kFromStringLength
                          ? "from_string_length"
                      : f.scale == InstrumentFitOptions::Scale::kWorldIsMillimetres ? "world_is_mm"
                                                                                    : "given";
  return {{"fit",
           {{"scale", scale},
            {"world_units_per_mm", f.world_units_per_mm},
            {"max_iterations", f.max_iterations},
            {"convergence_mm", f.convergence_mm},
            {"point_gate_factor", f.point_gate_factor},
            {"min_point_gate_mm", f.min_point_gate_mm},
            {"max_point_gate_mm", f.max_point_gate_mm},
            {"frame_gate_sigmas", f.frame_gate_sigmas},
            {"min_spread_mm", f.min_spread_mm},
            {"min_observations_per_point", f.min_observations_per_point},
            {"min_front_agreement", f.min_front_agreement},
            {"strings",
             {{"spacing",
               f.strings.spacing == StringGeometryOptions::Spacing::kInstrument
                   ? "instrument"
                   : "even_between_labels"},
              {"min_front_margin_mm", f.strings.min_front_margin_mm},
              {"min_front_angle_deg", f.strings.min_front_angle_deg},
              {"max_edge_angle_deg", f.strings.max_edge_angle_deg},
              {"world_units_per_mm", f.strings.world_units_per_mm}}}}},
          {"smoothing",
           {{"sigma_frames", o.smoothing.sigma_frames},
            {"radius_frames", o.smoothing.radius_frames},
            {"max_fill_gap_frames", o.smoothing.max_fill_gap_frames},
            {"max_end_hold_frames", o.smoothing.max_end_hold_frames},
            {"replace_high_residual", o.smoothing.replace_high_residual}}},
          {"smoothing_candidates_frames", o.smoothing_candidates_frames},
          {"num_threads", o.num_threads}};
}

StatusOr<InstrumentStageSummary> RunInstrumentStage(const InstrumentStageOptions& options,
                                                    const CaptureContext& capture,
                                                    Progress& progress) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  const ResultFolder result(options.result_dir);
  // The triangulation read here must come from the capture given.
  ARCO_RETURN_IF_ERROR(result.CheckInputsMatch(capture.inputs));
  ARCO_ASSIGN_OR_RETURN(Json manifest, result.ReadManifest());
  TriangulateStageResult triangulation;
  triangulation.summary.units = manifest.value("units", "unknown");
  ARCO_ASSIGN_OR_RETURN(triangulation.points3d, result.ReadPoints3d(kTriangulationStage));
  ARCO_ASSIGN_OR_RETURN(InstrumentRecord record,
                        RunInstrumentStage(options, capture, triangulation, progress));
  ARCO_RETURN_IF_ERROR(result.WriteInstrument(record));
  return std::move(record.summary);
}

StatusOr<InstrumentRecord> RunInstrumentStage(const InstrumentStageOptions& options,
                                              const CaptureContext& capture,
                                              const TriangulateStageResult& triangulation,
                                              Progress& /*progress*/) {
  const NpyArray<double>& points = triangulation.points3d;
  const InstrumentModel& model = *capture.instrument;
  const int64_t frames = points.shape[0];
  const int num_k = static_cast<int>(model.keypoint_names().size());
  std::vector<int> columns;
  for (const std::string& name : model.keypoint_names())
    columns.push_back(capture.layout.Find(name));
  std::vector<Eigen::Matrix3Xd> keypoints(static_cast<size_t>(frames));
  std::vector<FrontHint> hints(static_cast<size_t>(frames));
  // One camera: the instrument was placed by a PnP of its nominal points, which says where
  // its front is; the performer's points were put at an assumed depth and say nothing.
  const bool one_view = capture.view_to_camera.size() == 1;
  const std::vector<Eigen::Vector3d> nominal = NominalPoseKeypointsInInstrument(model);
  for (int64_t f = 0; f < frames; ++f) {
    Eigen::Matrix3Xd& m = keypoints[static_cast<size_t>(f)];
    m.resize(3, num_k);
    for (int k = 0; k < num_k; ++k) m.col(k) = PointAt(points, f, columns[static_cast<size_t>(k)]);
    if (one_view) {
      std::vector<Eigen::Vector3d> from, to;
      for (int k = 0; k < num_k; ++k) {
        from.push_back(nominal[static_cast<size_t>(k)]);
        to.push_back(m.col(k));
      }
      AlignmentOptions similarity;
      similarity.estimate_scale = true;
      hints[static_cast<size_t>(f)].value.setConstant(std::numeric_limits<double>::quiet_NaN());
      if (const auto a = AlignPoints(from, to, {}, similarity)) {
        hints[static_cast<size_t>(f)].kind = FrontHint::Kind::kFrontDirection;
        hints[static_cast<size_t>(f)].value =
            a->target_from_source.rotation * Eigen::Vector3d::UnitZ();
      }
      continue;
    }
    // The performer sits behind the instrument: the shoulders' midpoint says where the
    // back is (strings.h FrontHint).
    hints[static_cast<size_t>(f)].kind = FrontHint::Kind::kPerformerPoint;
    hints[static_cast<size_t>(f)].value =
        0.5 * (PointAt(points, f, kLeftShoulder) + PointAt(points, f, kRightShoulder));
  }
  InstrumentFitOptions fit_options = options.fit;
  if (triangulation.summary.units == "mm")
    fit_options.scale = InstrumentFitOptions::Scale::kWorldIsMillimetres;
  fit_options.num_threads = options.num_threads;
  StatusOr<InstrumentFit> fit = FitInstrument(model, keypoints, hints, fit_options);
  // FitInstrument's messages start "instrument fit: "; the context is the file it fitted.
  if (!fit.ok()) {
    return fit.status().WithContext(
        ResultFolder(options.result_dir).Points3dPath(kTriangulationStage));
  }
  PoseSmoothingOptions smoothing = options.smoothing;
  if (!options.smoothing_candidates_frames.empty()) {
    // Probes: every string's two ends, where the contacts lie.
    std::vector<Eigen::Vector3d> probes;
    for (const StringSegment& g : fit->instrument.strings_in_instrument) {
      probes.push_back(g.nut);
      probes.push_back(g.bridge);
    }
    smoothing.sigma_frames =
        LeaveOneOutSigmaFrames(fit->frames, probes, options.smoothing_candidates_frames);
  }
  const std::vector<InstrumentFramePose> poses = SmoothFramePoses(fit->frames, smoothing);
  InstrumentStageSummary summary;
  summary.smoothing_sigma_frames = smoothing.sigma_frames;
  for (const std::string& w : fit->summary.warnings) summary.warnings.push_back("instrument: " + w);
  if (fit->instrument.order.ambiguous) {
    summary.warnings.push_back("instrument: string order ambiguous: " +
                               fit->instrument.order.warning);
  }
  const double s = fit->instrument.world_units_per_mm;
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  // Strings (F, 4, 2, 3) and the placed template keypoints (F, K, 3), world scaled to mm.
  InstrumentRecord record;
  NpyArray<double>& strings = record.strings_mm;
  NpyArray<double>& placed = record.keypoints_mm;
  strings.shape = {frames, model.num_strings(), 2, 3};
  strings.data.assign(static_cast<size_t>(frames * model.num_strings() * 6), kNaN);
  placed.shape = {frames, num_k, 3};
  placed.data.assign(static_cast<size_t>(frames * num_k * 3), kNaN);
  int with_pose = 0;
  for (int64_t f = 0; f < frames; ++f) {
    const InstrumentFramePose& p = poses[static_cast<size_t>(f)];
    if (!p.has_pose()) continue;
    ++with_pose;
    const std::vector<StringSegment> seg = StringsAt(fit->instrument, p.world_from_instrument);
    for (int i = 0; i < model.num_strings(); ++i) {
      const Eigen::Vector3d nut_mm = PointInMm(seg[static_cast<size_t>(i)].nut, s);
      const Eigen::Vector3d bridge_mm = PointInMm(seg[static_cast<size_t>(i)].bridge, s);
      for (int c = 0; c < 3; ++c) {
        strings.at(f, i, 0, c) = nut_mm[c];
        strings.at(f, i, 1, c) = bridge_mm[c];
      }
    }
    for (int k = 0; k < num_k; ++k) {
      const Eigen::Vector3d& t = fit->instrument.keypoints_in_instrument[static_cast<size_t>(k)];
      if (!t.allFinite()) continue;
      const Eigen::Vector3d w = PointInMm(p.world_from_instrument * t, s);
      for (int c = 0; c < 3; ++c) placed.at(f, k, c) = w[c];
    }
  }
  const InstrumentFitSummary& fs = fit->summary;
  summary.instrument = model.name();
  summary.frames = frames;
  summary.frames_with_pose = with_pose;
  summary.frames_high_residual = fs.frames_high_residual;
  summary.median_rms_residual_mm = fs.median_rms_residual_mm;
  summary.front_agreement = fs.front_agreement;
  summary.string_order_ambiguous = fit->instrument.order.ambiguous;
  summary.labels_agree = fit->instrument.order.labels_agree;
  summary.world_units_per_mm = s;
  record.instrument = model.name();
  record.a4_hz = capture.manifest.tuning_a4_hz;
  record.world_units_per_mm = s;
  record.keypoint_names = model.keypoint_names();
  record.summary = summary;
  record.inputs = SelectInputs(capture.inputs, {kManifestInput});
  return record;
}

}  // namespace arco::pipeline
