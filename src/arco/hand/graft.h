// Wrist graft (the paper's Eq. 1): rigidly move the model hand so that its
// joints best match the body detector's hand joints, i.e. find
//   (R, t) = argmin sum_k w_k rho(|R p_k + t - q_k|)
// over the finite body keypoints q_k (weighted, optionally robust Kabsch from
// arco_geometry AlignPoints), and apply it to the hand pose:
//   world_from_wrist' = R world_from_wrist,  wrist' = R wrist + t.
// The joint angles are untouched. With pin_wrist the model wrist is placed on
// the body wrist and only the rotation about it is solved.
#pragma once

#include <string>
#include <vector>

#include "arco/hand/kinematics.h"

namespace arco::hand {

struct WristGraftOptions {
  bool pin_wrist = false;     // translation fixed: model wrist onto the body wrist
  double robust_loss_mm = 0;  // Cauchy scale; 0 = plain least squares
  Status Validate() const;
};

struct WristGraftResult {
  bool ok = false;
  std::string problem;
  HandPose pose;  // the grafted pose (the input pose when !ok)
  // The move applied to the input pose (world to world): pose.world_from_wrist =
  // moved_from_input * hand.world_from_wrist.
  RigidMatrix3d moved_from_input;
  double rms_mm = 0;  // weighted rms joint distance after the graft
  int num_points = 0;
};

// `weights` (e.g. detector scores) per keypoint, empty = all 1; NaN body
// keypoints are ignored. Fails (ok = false) with fewer than 3 usable,
// non-collinear points (pin_wrist: the wrist and 2 more). Throws
// std::invalid_argument on a weights size other than 0 or 21.
WristGraftResult GraftHandAtWrist(const HandModel& model,
                                  const HandPose& hand,
                                  const HandPointsMm& body_hand_in_world_mm,
                                  const std::vector<double>& weights,
                                  const WristGraftOptions& options);

}  // namespace arco::hand
