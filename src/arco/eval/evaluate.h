// `arco eval`: every method in a result folder scored against truth
// (docs/evaluation.md).
//
// Methods: the stages of RESULT_DIR/result.json that have a points3d file
// (triangulation, vision, paper, arco, ...; any subset), read in the result's
// keypoint layout. A stage may also list a per-frame contact annotation
// (files.contact, CSV with the columns frame, string, finger, contact_x_mm,
// contact_y_mm, contact_z_mm as truth/contact.csv): then string and finger
// identification are scored.
// Truth: a synthetic truth folder (arco synth's truth/, read by synth/truth_folder.h:
// points3d.npy, contact.csv, pitch.csv are scored), or points JSONs of `arco triangulate --view
// ...` (manually labelled views triangulated: the paper's real-data protocol), one per labelled
// frame. Pitch: RESULT_DIR/pitch.csv (or --pitch FILE) against truth/pitch.csv.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "arco/eval/metrics.h"
#include "arco/util/json_io.h"
#include "arco/util/number_range.h"
#include "arco/util/status.h"

namespace arco::eval {

// The declared ranges of EvalRequest (Validate(); `arco eval` declares the same).
inline constexpr NumberRange kPckThresholdRangeMm = AboveZero(1000);
inline constexpr NumberRange kJointLimitToleranceRangeDeg = Closed(0, 180);
inline constexpr NumberRange kTruthFrameRange = Closed(0, 1e9);  // frames.first may be 0

struct EvalRequest {
  std::string result_dir;
  std::string truth;                  // synthetic truth folder, or empty when `labels` are given
  std::vector<std::string> labels;    // points JSONs of labelled views, one frame each ...
  std::vector<int64_t> truth_frames;  // ... and the frame number each labels (manifest numbering)
  std::string pitch_csv;  // optional estimate; default RESULT_DIR/pitch.csv when present
  EvalOptions metrics;
  double joint_limit_tolerance_deg = 5.0;

  // Every number in its range; one truth frame per labels file when labels are given.
  Status Validate() const;
};

struct EvalReport {
  std::string truth_kind;  // "synthetic" or "labels"
  int truth_frames = 0;    // frames with truth
  int contact_frames = 0;
  int truth_joint_limit_violations = -1;  // the truth's left hand against arco's limits
  std::string units;
  std::vector<MethodMetrics> methods;
  std::optional<PitchMetrics> pitch;
  std::vector<double> truth_f0_hz, estimate_f0_hz;  // per frame, 0 = unvoiced (plots)
  double fps = 30;
  std::vector<std::string> warnings;

  Json ToJson(const EvalOptions& options) const;
  std::string MarkdownTable(const EvalOptions& options) const;
};

StatusOr<EvalReport> Evaluate(const EvalRequest& request);

// The scoring options of a request as applied, recorded in eval.json "options":
// pck_thresholds_mm, joint_limit_tolerance_deg, truth_frames (labelled frames; empty for a
// synthetic truth). File paths are not repeated: they are the command's arguments.
Json ToJson(const EvalRequest& request);

// Reads a contact CSV (refine/contacts_csv.h: columns by header name; extra columns
// ignored) as a track of num_frames frames; rows past the last frame are ignored.
StatusOr<ContactTrack> ReadContactCsv(const std::string& path, int num_frames);

// Joint limits of arco's default left hand as geometric PIP/DIP bounds, with the
// rest pose's geometric angles (hand/hand_model.h).
HandJointLimitsDeg DefaultLeftHandLimits();

}  // namespace arco::eval
