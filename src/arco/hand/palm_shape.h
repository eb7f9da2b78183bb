// The performer's palm: where the five finger bases (thumb CMC, index..little MCP) sit in
// the wrist frame, estimated from the triangulated hand over the take instead of taken
// from the average hand (hand_model.cc, DefaultRightRestPointsMm).
//
// Why: on SPD's real cellist (docs/hand.md, "The palm fitted to the performer") the
// average hand's bases sit 2-4 mm from the performer's in the fitted wrist frame, and the
// model fit spreads that shape error over every joint: the vision fit's MCPs were biased
// by 2-4 mm over the whole take while the triangulated MCPs were biased by 1-2 mm.
//
// Method: a generalised Procrustes mean (Gower 1975) of the six palm points (wrist and
// the five bases), which are rigid to within skin motion: each frame with all six points
// is aligned rigidly (Kabsch) onto the current mean, frames whose alignment residual is
// beyond `gate` robust deviations are dropped, and the mean is the per-coordinate median
// of the aligned frames; a few rounds. The mean is then expressed about its wrist and
// rotated (about the wrist) onto the model's own bases, so the wrist frame keeps the
// model's convention (its joint axes are defined in it). A base whose estimate is more
// than `max_shift_mm` from the model's keeps the model's (a bad triangulation must not
// deform the hand).
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "arco/hand/hand_model.h"
#include "arco/hand/kinematics.h"
#include "arco/util/status.h"

namespace arco::hand {

struct PalmShapeOptions {
  // On SPD's real take every row's left hand is 0.05-0.37 mm nearer SPD's with it
  // (docs/accuracy.md, "A real take"); `arco run --average-palm` turns it off.
  bool enabled = true;
  int min_frames = 30;         // frames with all six palm points finite, after the gate
  int rounds = 3;              // Procrustes rounds, >= 1
  double gate = 3.0;           // frame gate in robust deviations of the alignment residual
  double max_shift_mm = 12.0;  // a base moved further keeps the model's
  Status Validate() const;
};

struct PalmShapeEstimate {
  // Bases (thumb CMC, index, middle, ring, little MCP) in the model's wrist frame, mm.
  std::array<Eigen::Vector3d, kNumFingers> base_in_wrist_mm;
  std::array<double, kNumFingers> shift_mm{};     // from the model's base
  std::array<uint8_t, kNumFingers> kept_model{};  // 1: beyond max_shift_mm
  int frames_used = 0;
  double median_residual_mm = 0;  // of the kept frames' alignment onto the final mean
};

// `frames`: triangulated keypoints per frame (mm, NaN = missing); `model`: the hand whose
// bases are refined (its side and wrist frame). Errors: fewer than min_frames usable
// frames (the message says how many), invalid options.
StatusOr<PalmShapeEstimate> EstimatePalmShape(const std::vector<HandPointsMm>& frames,
                                              const HandModel& model,
                                              const PalmShapeOptions& options);

}  // namespace arco::hand
