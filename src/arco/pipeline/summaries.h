// What each stage of the pipeline reports (pipeline/run_capture.h). Each summary writes
// itself to JSON (ToJson, next to the struct); the result folder records that JSON in
// result.json (pipeline/result_folder.h), so the entries are assembled in one place.
// Warnings are full sentences prefixed with the stage ("instrument: ...") for the terminal.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "arco/mocap/triangulate_sequence.h"
#include "arco/util/json_io.h"

namespace arco::pipeline {

struct TriangulateStageSummary {
  SequenceTriangulationSummary triangulation;
  std::string units;  // of the rig
  int64_t views = 0;
  int64_t keypoints = 0;
  // Stages of an existing result that the new triangulation removed (made from the old).
  std::vector<std::string> removed_stages;
};

struct InstrumentStageSummary {
  std::string instrument;  // model name
  int64_t frames = 0;
  int frames_with_pose = 0;  // after smoothing and gap filling
  int frames_high_residual = 0;
  double median_rms_residual_mm = 0;
  double front_agreement = 0;
  bool string_order_ambiguous = false;
  bool labels_agree = false;
  double world_units_per_mm = 0;      // the metric scale of the world
  double smoothing_sigma_frames = 0;  // the pose smoothing's kernel width as chosen
  std::vector<std::string> warnings;
};
// {frames, frames_with_pose, frames_high_residual, median_rms_residual_mm,
// front_agreement, string_order_ambiguous, labels_agree, smoothing_sigma_frames}.
Json ToJson(const InstrumentStageSummary& summary);

struct HandStageSummary {
  int64_t frames = 0;
  int frames_fitted = 0;
  int frames_interpolated = 0;  // short gaps between fitted frames (hand/pose_gaps.h)
  // Medians over the fitted frames of the per-frame RMS reprojection residual (dominated
  // by the few outlier detections a robust fit ignores) and of the per-frame median.
  double median_rms_residual_px = 0;
  double median_residual_px = 0;
  bool bone_lengths_from_data = false;  // false: the default hand's lengths
  bool palm_from_data = false;          // false: the average hand's palm
  int palm_frames = 0;                  // frames the palm was estimated from
  double palm_max_shift_mm = 0;         // largest base move from the average palm
  int palm_bases_kept = 0;              // bases beyond max_shift_mm, left where they were
  std::vector<std::string> warnings;
};
// {frames, frames_fitted, frames_interpolated, median_rms_residual_px, median_residual_px,
// bone_lengths_from_data, palm_from_data, palm_frames, palm_max_shift_mm,
// palm_bases_kept}.
Json ToJson(const HandStageSummary& summary);

struct PitchStageSummary {
  bool ran = false;   // false: the capture has no audio (a warning says so)
  std::string audio;  // the file tracked
  double duration_s = 0;
  double voiced_fraction = 0;
  int64_t notes = 0;
  std::vector<std::string> warnings;
};
// {duration_s, voiced_fraction, notes}.
Json ToJson(const PitchStageSummary& summary);

}  // namespace arco::pipeline
