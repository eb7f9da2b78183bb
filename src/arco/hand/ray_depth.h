// One view: each keypoint of a fitted hand moved along its own ray from the camera (issue
// 26 part 4).
//
// One camera fixes where each of the hand's keypoints lies across its ray, not how far
// along it: the fit's bones can tilt toward or away from the camera at almost no cost in
// the image. Where something else says where a keypoint is along some axis (the pressing
// fingertip's distance from the camera, from the contact the sound gives; a fingertip's
// place along its string, from the hand frame), the 21 keypoints' distances from the
// camera are solved together: those targets, the model's bone lengths, and each point
// near where the fit put it (least squares, each residual over its sigma). Every point
// stays on its ray, so the hand's image is what the fit made it; the model is then fitted
// to the moved points (FitHandToPoints3d), which keeps the joint limits.
//
// On the real take (SPD cello01, one camera, arco's refined hand), measured before this
// was built: the keypoints' depths along their rays made exact (an oracle) would put the
// left hand within 15 mm in the instrument's frame on 0.95 of frames (`shared`, seed 0)
// against 0.34; the hand's ring and little fingers lay 10-35 mm too near the camera.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "arco/hand/hand_model.h"
#include "arco/hand/kinematics.h"
#include "arco/util/status.h"

namespace arco::hand {

// Keypoint `keypoint` should have axis . p = coordinate_mm (p in world mm; axis a unit
// vector), within sigma_mm.
struct AxisTarget {
  int keypoint = 0;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
  double coordinate_mm = 0;
  double sigma_mm = 1;
};

struct RayDepthOptions {
  double bone_sigma_mm = 2.0;   // (0, 100]: a bone's length off the model's
  double stay_sigma_mm = 15.0;  // (0, 1e4]: a keypoint's distance off the fit's
  int max_iterations = 30;      // [1, 1000]
  Status Validate() const;
};

struct RayDepthResult {
  HandPose pose;              // the model fitted to the moved keypoints
  double median_move_mm = 0;  // the keypoints' median |move| along their rays
};

// The hand `pose` of `model` seen from `camera_centre_mm`, its keypoints moved along their
// rays to meet `targets` (above). nullopt where the options are invalid, a keypoint sits at the
// camera's centre, a target names no keypoint or has a non-unit axis or sigma <= 0, or the fit
// fails.
std::optional<RayDepthResult> PlaceKeypointsAlongRays(const HandModel& model,
                                                      const Eigen::Vector3d& camera_centre_mm,
                                                      const HandPose& pose,
                                                      const std::vector<AxisTarget>& targets,
                                                      const RayDepthOptions& options);

}  // namespace arco::hand
