// A rigid per-capture instrument template fitted to triangulated keypoints over a whole
// clip, then one rigid pose per frame (so strings do not wobble with keypoint noise, and
// frames with some keypoints missing still get strings).
//
// Input: per frame a 3 x K matrix of keypoints in the world (calibration units), columns
// in InstrumentModel::keypoint_names() order, NaN columns = missing. Only the rigid body
// keypoints are used (not the bow's frog and tip).
//
// Method:
// 1. Scale: the median over frames of the nut-centre to bridge-centre distance (frames
//    with all four nut/bridge points), divided by the model's string length, gives world
//    units per mm (InstrumentFitOptions::Scale::kFromStringLength; one noisy frame cannot
//    set the scale as in the SPD code). Recomputed at the end over the inlier frames only.
// 2. Initial template: among the frames with the most keypoints, the one whose pairwise
//    distances are closest (mean absolute difference) to the per-pair medians over the clip.
// 3. Iterate: align the template to every frame (rigid_align.h: least squares, exhaustive
//    3-point hypotheses when a point is off by more than the gate); the point gate is
//    point_gate_factor x the median point residual of the previous pass (clamped to
//    [min_point_gate_mm, max_point_gate_mm]); frames whose RMS residual exceeds
//    median + frame_gate_sigmas x 1.4826 MAD are left out; each template point becomes the
//    per-coordinate median of its inlier observations mapped into the template frame.
//    Stops when no template point moves more than convergence_mm.
// 4. The instrument frame (strings.h) is built from the template's nut and bridge points;
//    the front side comes from a majority vote of the per-frame hints mapped into the
//    template; a split vote or hints near the top-plate plane make the order ambiguous.
// 5. A final per-frame robust pose against the template in the instrument frame
//    (FitFramePose, also usable on new frames), with its residual in mm.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "arco/instrument/instrument_model.h"
#include "arco/instrument/strings.h"
#include "arco/util/status.h"

namespace arco {

struct InstrumentFitOptions {
  enum class Scale {
    kFromStringLength,    // world units are arbitrary (Metashape): see the header comment
    kWorldIsMillimetres,  // world units are mm already
    kGiven,               // use world_units_per_mm
  };
  Scale scale = Scale::kFromStringLength;
  double world_units_per_mm = 0;  // for kGiven

  int max_iterations = 20;
  double convergence_mm = 0.01;
  double point_gate_factor = 4.0;  // x median point residual
  double min_point_gate_mm = 5.0;
  double max_point_gate_mm = 60.0;     // also the gate of the first pass
  double frame_gate_sigmas = 4.0;      // frame RMS outlier gate (robust sigmas)
  double min_spread_mm = 3.0;          // inlier points must not be (nearly) collinear
  int min_observations_per_point = 3;  // a template point needs this many inlier frames
  StringGeometryOptions strings;       // spacing and ambiguity thresholds
  // Fraction of voting frames that must agree on the front side.
  double min_front_agreement = 0.8;
  int num_threads = 1;  // 0 = all cores; results do not depend on it

  Status Validate() const;
};

enum class FrameFitStatus {
  kOk,
  kHighResidual,  // has a pose, but its RMS residual is an outlier for the clip
  kTooFewPoints,  // fewer than 3 non-collinear inlier points: no pose
};
const char* FrameFitStatusName(FrameFitStatus status);

struct InstrumentFramePose {
  FrameFitStatus status = FrameFitStatus::kTooFewPoints;
  bool has_pose() const { return status != FrameFitStatus::kTooFewPoints; }
  SimMatrix3d world_from_instrument;  // valid when has_pose(); scale = world units per mm
  double rms_residual_mm = 0;  // over the inlier keypoints; NaN without a pose
  int num_observed = 0;        // rigid keypoints finite in this frame and in the template
  int num_inliers = 0;
  uint32_t inlier_mask = 0;  // bit k = keypoint k (keypoint_names() order) used
  // Set by SmoothFramePoses when the pose comes from the neighbours only (a filled gap or
  // a replaced kHighResidual frame).
  bool filled = false;
};

struct InstrumentTemplate {
  // Keypoints in the instrument frame (mm), keypoint_names() order; NaN for the bow points
  // and for points observed in too few frames.
  std::vector<Eigen::Vector3d> keypoints_in_instrument;
  std::vector<StringSegment> strings_in_instrument;  // index = string - 1
  StringOrderReport order;
  double world_units_per_mm = 1;
  double nut_bridge_spread_rel = 0;  // 1.4826 MAD / median of the per-frame distances
  int scale_frames = 0;              // frames in that median
};

struct InstrumentFitSummary {
  int iterations = 0;
  bool converged = false;
  int num_frames = 0;
  int frames_with_pose = 0;
  int frames_high_residual = 0;
  int frames_in_template = 0;  // frames used by the last template update
  double median_rms_residual_mm = 0;
  double point_gate_mm = 0;    // the final gate
  double front_agreement = 0;  // fraction of voting frames on the chosen side
  int front_votes = 0;
  std::vector<std::string> warnings;
};

struct InstrumentFit {
  InstrumentTemplate instrument;
  std::vector<InstrumentFramePose> frames;
  InstrumentFitSummary summary;
};

// `hints`: one FrontHint for the whole clip, or one per frame (non-finite entries do not
// vote). Throws std::invalid_argument for a keypoint matrix with the wrong column count or
// a hint count other than 1 or the frame count. Errors (Status): bad options, an empty
// clip, no frame with all four nut/bridge points, nut and bridge coincident, no frame
// with three usable points, nut/bridge template points not recoverable.
StatusOr<InstrumentFit> FitInstrument(const InstrumentModel& model,
                                      const std::vector<Eigen::Matrix3Xd>& keypoints_in_world,
                                      const std::vector<FrontHint>& hints,
                                      const InstrumentFitOptions& options = {});

// Robust rigid pose of the fitted template in one frame (status kOk or kTooFewPoints;
// the clip-level kHighResidual is decided by FitInstrument).
InstrumentFramePose FitFramePose(const InstrumentTemplate& instrument,
                                 const Eigen::Matrix3Xd& keypoints_in_world,
                                 double point_gate_mm,
                                 double min_spread_mm = 3.0);

// RMS distance (mm) between the template placed by `world_from_instrument` and the keypoints in
// `inlier_mask` (e.g. after smoothing the pose); NaN when none is finite.
double PoseResidualMm(const InstrumentTemplate& instrument,
                      const SimMatrix3d& world_from_instrument,
                      const Eigen::Matrix3Xd& keypoints_in_world,
                      uint32_t inlier_mask);

// The strings in the world for one pose (index = string - 1).
inline std::vector<StringSegment> StringsAt(const InstrumentTemplate& instrument,
                                            const SimMatrix3d& world_from_instrument) {
  return StringsInWorld(instrument.strings_in_instrument, world_from_instrument);
}

}  // namespace arco
