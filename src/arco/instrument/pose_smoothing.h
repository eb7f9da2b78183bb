// Optional temporal smoothing of per-frame instrument poses. The instrument is rigid, so
// smoothing the pose (not the keypoints or the strings) keeps the strings straight and
// evenly spaced; recompute strings and contacts from the smoothed poses afterwards:
//
//   InstrumentFit fit = *FitInstrument(model, keypoints, hints);
//   std::vector<InstrumentFramePose> smooth = SmoothFramePoses(fit.frames, {});
//   for (frame f with smooth[f].has_pose())
//     strings = StringsAt(fit.instrument, smooth[f].world_from_instrument);  // template_fit.h
//     point   = strings[s - 1].PointAtFraction(contact.fraction_from_bridge);
//
// Method: a Gaussian kernel over time (sigma_frames, truncated at radius_frames) over the
// frames that have a pose with status kOk; translation by the weighted mean; rotation by
// the weighted quaternion average of Markley et al. 2007 (arco_geometry's
// AverageQuaternions: the eigenvector of sum w q q^T with the largest eigenvalue), which
// does not depend on order or on the quaternions' signs. The scale (world units per mm) is constant
// per clip and kept.
#pragma once

#include <vector>

#include "arco/instrument/template_fit.h"
#include "arco/util/status.h"

namespace arco {

struct PoseSmoothingOptions {
  double sigma_frames = 2.0;  // Gaussian kernel width in frames
  int radius_frames = 0;      // kernel half-width; 0 = ceil(3 sigma)
  // Frames without a pose (or with kHighResidual) get a smoothed pose when kOk frames
  // exist on BOTH sides within this many frames; 0 = never fill.
  int max_fill_gap_frames = 0;
  // Frames without a pose before the clip's first kOk frame or after its last get the
  // smoothed pose of the posed frames beside them when within this many frames of one
  // (a held instrument barely moves in a few frames; its points may be too few at the
  // take's first frames, e.g. a bridge hidden from a one camera); 0 = never. At most
  // the kernel's radius takes effect (no posed frame lies farther in the kernel).
  int max_end_hold_frames = 0;
  // When true, kHighResidual frames keep their own pose out of the average but receive
  // the smoothed pose of their neighbours (if any lie within radius_frames).
  bool replace_high_residual = true;

  Status Validate() const;
};

// Returns one entry per frame: the smoothed pose (status kOk), or the input entry
// unchanged when no kOk frame lies within the kernel (or, for frames without a pose, the
// gap is larger than max_fill_gap_frames, or the clip's end farther than
// max_end_hold_frames). rms_residual_mm, inlier_mask etc. are copied
// from the input; recompute residuals with PoseResidualMm when needed. Throws
// std::invalid_argument for options that fail Validate().
std::vector<InstrumentFramePose> SmoothFramePoses(const std::vector<InstrumentFramePose>& frames,
                                                  const PoseSmoothingOptions& options = {});

// The kernel width among `candidates_frames` whose smoothing best predicts each kOk frame's
// `probe_points_in_instrument` (placed by that frame's own pose) from the other kOk frames
// around it: leave-one-out cross-validation (Wahba 1990, ch. 4) of a Gaussian-weighted mean
// of the placed points, the average over frames of the squared distance. Detector noise
// that is independent from frame to frame counts against a narrow kernel, the
// instrument's own motion against a wide one. `candidates_frames[0]` when fewer than
// `min_frames` frames have a pose. Candidates must be > 0.
double LeaveOneOutSigmaFrames(const std::vector<InstrumentFramePose>& frames,
                              const std::vector<Eigen::Vector3d>& probe_points_in_instrument,
                              const std::vector<double>& candidates_frames,
                              int min_frames = 30);

}  // namespace arco
