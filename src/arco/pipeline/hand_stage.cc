#include "arco/pipeline/hand_stage.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "arco/hand/pose_gaps.h"
#include "arco/pipeline/result_folder.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/util/parallel.h"
#include "arco/util/stats.h"

namespace arco::pipeline {
namespace {

constexpr int kLeftHandFirst = wholebody::kLeftHandFirst;

}  // namespace

Status HandStageOptions::Validate() const {
  if (result_dir.empty()) return Status::Error("result_dir is empty");
  if (chunk_frames < 1) return Status::Error("chunk_frames must be >= 1");
  if (num_threads < 0) return Status::Error("num_threads must be >= 0");
  ARCO_RETURN_IF_ERROR(bones.Validate().WithContext("bones"));
  ARCO_RETURN_IF_ERROR(palm.Validate().WithContext("palm"));
  ARCO_RETURN_IF_ERROR(one_view_depth.Validate().WithContext("one_view_depth"));
  ARCO_RETURN_IF_ERROR(gaps.Validate().WithContext("gaps"));
  if (!(one_view_bone_quantile >= 0.5 && one_view_bone_quantile < 1))
    return Status::Error("one_view_bone_quantile must be in [0.5, 1)");
  if (!(one_view_palm_bone_quantile >= 0.5 && one_view_palm_bone_quantile < 1))
    return Status::Error("one_view_palm_bone_quantile must be in [0.5, 1)");
  if (!(one_view_thumb_bone_quantile >= 0.5 && one_view_thumb_bone_quantile < 1))
    return Status::Error("one_view_thumb_bone_quantile must be in [0.5, 1)");
  return fit.Validate().WithContext("fit");
}

Json ToJson(const HandStageOptions& o) {
  const hand::HandFitOptions& f = o.fit;
  return {{"bones",
           {{"min_samples", o.bones.min_samples},
            {"mad_gate", o.bones.mad_gate},
            {"min_mad_mm", o.bones.min_mad_mm},
            {"min_ratio", o.bones.min_ratio},
            {"max_ratio", o.bones.max_ratio},
            {"correct_noise_bias", o.bones.correct_noise_bias},
            {"quantile", o.bones.quantile},
            {"palm_quantile", o.bones.palm_quantile},
            {"thumb_quantile", o.bones.thumb_quantile}}},
          {"palm",
           {{"enabled", o.palm.enabled},
            {"min_frames", o.palm.min_frames},
            {"rounds", o.palm.rounds},
            {"gate", o.palm.gate},
            {"max_shift_mm", o.palm.max_shift_mm}}},
          {"fit",
           {{"min_score", f.min_score},
            {"weight_by_score", f.weight_by_score},
            {"robust_loss_px", f.robust_loss_px},
            {"view_gate_px", f.view_gate_px},
            {"min_keypoints_per_view", f.min_keypoints_per_view},
            {"min_views", f.min_views},
            {"min_initial_points", f.min_initial_points},
            {"temporal_angle_weight_px_per_rad", f.temporal_angle_weight_px_per_rad},
            {"temporal_rotation_weight_px_per_rad", f.temporal_rotation_weight_px_per_rad},
            {"temporal_translation_weight_px_per_mm", f.temporal_translation_weight_px_per_mm},
            {"max_iterations", f.max_iterations}}},
          {"one_view_depth", {{"window_frames", o.one_view_depth.window_frames}}},
          {"gaps", {{"max_gap_frames", o.gaps.max_gap_frames}}},
          {"one_view_bone_quantile", o.one_view_bone_quantile},
          {"one_view_palm_bone_quantile", o.one_view_palm_bone_quantile},
          {"one_view_thumb_bone_quantile", o.one_view_thumb_bone_quantile},
          {"one_view_palm_as_one", o.one_view_palm_as_one},
          {"chunk_frames", o.chunk_frames},
          {"num_threads", o.num_threads}};
}

StatusOr<HandStageSummary> RunHandStage(const HandStageOptions& options,
                                        const CaptureContext& capture,
                                        Progress& progress) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  const ResultFolder result(options.result_dir);
  // The stages read here must come from the capture given.
  ARCO_RETURN_IF_ERROR(result.CheckInputsMatch(capture.inputs));
  InstrumentRecord instrument;
  ARCO_ASSIGN_OR_RETURN(instrument.world_units_per_mm, result.ReadWorldUnitsPerMm());
  TriangulateStageResult triangulation;
  ARCO_ASSIGN_OR_RETURN(triangulation.points3d, result.ReadPoints3d(kTriangulationStage));
  ARCO_ASSIGN_OR_RETURN(HandRecord record,
                        RunHandStage(options, capture, triangulation, instrument, progress));
  ARCO_RETURN_IF_ERROR(result.WriteHand(record));
  return std::move(record.summary);
}

StatusOr<HandRecord> RunHandStage(const HandStageOptions& options,
                                  const CaptureContext& capture,
                                  const TriangulateStageResult& triangulation,
                                  const InstrumentRecord& instrument,
                                  Progress& progress) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  const double s = instrument.world_units_per_mm;
  if (!(s > 0)) return Status::Error("hand stage: the instrument has no world_units_per_mm");
  // The triangulation and the views' cameras with the world in mm (the same pixels).
  const NpyArray<double> points_mm = PointsInMm(triangulation.points3d, s);
  const std::vector<Camera> cameras = ViewCamerasInMm(capture, s);
  ARCO_ASSIGN_OR_RETURN(const std::shared_ptr<const NpyArray<double>> k2d_read,
                        ReadKeypoints2d(capture));
  const NpyArray<double>& k2d = *k2d_read;
  const int64_t frames = points_mm.shape[0];
  const int64_t views = static_cast<int64_t>(cameras.size());
  std::vector<hand::HandPointsMm> left(static_cast<size_t>(frames));
  for (int64_t f = 0; f < frames; ++f) {
    for (int k = 0; k < hand::kNumHandKeypoints; ++k) {
      left[static_cast<size_t>(f)][k] = PointAt(points_mm, f, kLeftHandFirst + k);
    }
  }
  HandStageSummary summary;
  const hand::HandModel prior = hand::HandModel::Default(hand::HandSide::kLeft);
  hand::HandModel model = prior;
  // One camera: the 3D points were lifted at one depth per frame, the strings'
  // (track/monocular_lift.h): their distances are the bones' projections on a plane
  // parallel to the image, whole when a bone lies parallel to it, so a higher quantile of
  // them. On SPD's cellist the 75th percentile came within 10 % of most of her bones,
  // where the model's average hand has proximal phalanges 50 % too long
  // (docs/accuracy.md, "One camera").
  const bool one_view = views == 1;
  hand::BoneLengthOptions bone_options = options.bones;
  if (one_view) {
    bone_options.quantile = options.one_view_bone_quantile;
    bone_options.palm_quantile = options.one_view_palm_bone_quantile;
    bone_options.thumb_quantile = options.one_view_thumb_bone_quantile;
    bone_options.palm_as_one = options.one_view_palm_as_one;
  }
  StatusOr<hand::BoneLengthEstimate> bones = hand::EstimateBoneLengths(left, prior, bone_options);
  if (bones.ok()) {
    StatusOr<hand::HandModel> sized = prior.WithBoneLengths(bones->lengths_mm);
    if (sized.ok()) model = *sized;
  } else {
    summary.warnings.push_back("hand: default bone lengths (" + bones.status().message() + ")");
  }
  if (one_view && bones.ok())
    summary.warnings.push_back(
        "hand: one camera: bone lengths from the hand's image at the strings' depth (a high "
        "quantile of their projections), the average palm (its shape needs two views)");
  if (options.palm.enabled && !one_view) {
    StatusOr<hand::PalmShapeEstimate> palm = hand::EstimatePalmShape(left, model, options.palm);
    StatusOr<hand::HandModel> palmed =
        palm.ok() ? model.WithBasePoints(palm->base_in_wrist_mm) : palm.status();
    if (palmed.ok()) {
      model = *palmed;
      summary.palm_from_data = true;
      summary.palm_frames = palm->frames_used;
      for (int f = 0; f < hand::kNumFingers; ++f) {
        // The largest move applied: a base that keeps the model's did not move.
        if (!palm->kept_model[f]) {
          summary.palm_max_shift_mm = std::max(summary.palm_max_shift_mm, palm->shift_mm[f]);
        }
        summary.palm_bases_kept += palm->kept_model[f];
      }
    } else {
      summary.warnings.push_back("hand: the average palm (" + palmed.status().message() + ")");
    }
  }
  const int chunk = options.chunk_frames;
  const int64_t num_chunks = (frames + chunk - 1) / chunk;
  HandRecord record;
  std::vector<std::optional<hand::HandPose>>& fitted = record.hands;
  fitted.resize(static_cast<size_t>(frames));
  std::vector<double> residual_px(static_cast<size_t>(frames), kNaN);
  std::vector<double> median_residual_px(static_cast<size_t>(frames), kNaN);
  // One camera: its view is all there is (the hand's depth starts on the string plane,
  // track/monocular_lift.h, and the sound corrects it in the refinement).
  hand::HandFitOptions fit_options = options.fit;
  if (one_view) fit_options.min_views = 1;
  progress.SetTotal(frames);
  ParallelFor(
      num_chunks,
      options.num_threads,
      [&](int64_t ci, int) {
        std::optional<hand::HandPose> previous;
        const int64_t end = std::min(frames, (ci + 1) * chunk);
        for (int64_t f = ci * chunk; f < end; ++f) {
          std::vector<hand::HandKeypoints2d> obs(static_cast<size_t>(views));
          for (int64_t v = 0; v < views; ++v) {
            for (int k = 0; k < hand::kNumHandKeypoints; ++k) {
              const int64_t p = kLeftHandFirst + k;
              obs[static_cast<size_t>(v)].pixels[k] =
                  Eigen::Vector2d(k2d.at(f, v, p, 0), k2d.at(f, v, p, 1));
              const double score = k2d.at(f, v, p, 2);
              obs[static_cast<size_t>(v)].scores[k] = std::isfinite(score) ? score : 0.0;
            }
          }
          hand::HandFitInit init;
          init.points_in_world_mm = left[static_cast<size_t>(f)];
          init.previous_pose = previous;
          const hand::HandFitResult r =
              hand::FitHandMultiView(model, cameras, obs, init, fit_options);
          if (r.ok) {
            fitted[static_cast<size_t>(f)] = r.pose;
            residual_px[static_cast<size_t>(f)] = r.rms_residual_px;
            median_residual_px[static_cast<size_t>(f)] = r.median_residual_px;
            previous = r.pose;
          }
        }
        progress.Advance(end - ci * chunk);
      },
      1);
  // Short gaps between fitted frames (hand/pose_gaps.h); a filled frame has no residual.
  ARCO_ASSIGN_OR_RETURN(summary.frames_interpolated, hand::FillHandPoseGaps(options.gaps, &fitted));
  if (one_view) {
    // The fingertips at the depth of the strings: the lifted fingertips' median distance
    // from the camera (the lift put the hand at one depth per frame).
    const Eigen::Vector3d centre = cameras[0].CenterInWorld();
    std::vector<double> tip_distance(static_cast<size_t>(frames), kNaN);
    for (int64_t f = 0; f < frames; ++f) {
      std::vector<double> d;
      for (hand::Finger finger : {hand::Finger::kIndex,
                                  hand::Finger::kMiddle,
                                  hand::Finger::kRing,
                                  hand::Finger::kLittle}) {
        const Eigen::Vector3d& p = left[static_cast<size_t>(f)][hand::TipKeypoint(finger)];
        if (p.allFinite()) d.push_back((p - centre).norm());
      }
      if (!d.empty()) tip_distance[static_cast<size_t>(f)] = UpperMedian(d);
    }
    ARCO_ASSIGN_OR_RETURN(
        const hand::OneViewDepthSummary moved,
        hand::AlignHandDepth(model, centre, tip_distance, options.one_view_depth, &fitted));
    summary.warnings.push_back(
        "hand: one camera: the hand's depth is the strings' (moved " +
        std::to_string(static_cast<int>(std::lround(moved.median_shift_mm))) +
        " mm along the rays, median of " + std::to_string(moved.frames_moved) + " frames)");
  }
  int ok = 0;
  // Per frame: the RMS (dominated by the few outlier detections a robust fit
  // ignores) and the median residual; the summary gives the median over frames of both
  // (the upper middle element when even).
  std::vector<double> res, res_median;
  for (int64_t f = 0; f < frames; ++f) {
    if (!std::isfinite(residual_px[static_cast<size_t>(f)])) continue;  // not fitted
    ++ok;
    res.push_back(residual_px[static_cast<size_t>(f)]);
    res_median.push_back(median_residual_px[static_cast<size_t>(f)]);
  }
  summary.frames = frames;
  summary.frames_fitted = ok;
  summary.median_rms_residual_px = res.empty() ? kNaN : UpperMedian(res);
  summary.median_residual_px = res_median.empty() ? kNaN : UpperMedian(res_median);
  summary.bone_lengths_from_data = bones.ok();
  for (int k = 0; k < hand::kNumHandKeypoints; ++k) {
    record.bone_lengths_mm[static_cast<size_t>(k)] = k == 0 ? 0.0 : model.bone_length_mm(k);
  }
  record.rest_points_mm = model.rest_points_mm();
  record.summary = summary;
  record.inputs =
      SelectInputs(capture.inputs, {kManifestInput, kCalibrationInput, kKeypoints2dInput});
  return record;
}

}  // namespace arco::pipeline
