// View-weighted fusion for detectors that give a 3D hand per view (e.g.
// MediaPipe world landmarks, a per-view hand-model regressor): the paper's
// step 3. Each view's 3D hand is fitted with the hand model (bone lengths
// fixed, limits as bounds) after rotating it into the world and normalising its
// size; the fused pose averages the joint rotations over views with weights
//   w_v = confidence_v * max(|cos angle(palm normal, ray to camera)|, floor)^power
// (views that see the palm or the back of the hand face-on count most; an
// edge-on view least), using the order-independent eigenvector quaternion
// average of Markley et al. 2007 (arco_geometry AverageQuaternions). Averaged
// joint rotations are projected back onto each joint's axes and clamped into
// the limits.
//
// The fused hand is root-relative: its wrist sits at the world origin. Graft it
// onto the body detector's hand with GraftHandAtWrist (graft.h).
#pragma once

#include <string>
#include <vector>

#include "arco/camera/camera.h"
#include "arco/hand/fit.h"

namespace arco::hand {

struct ViewHand3d {
  // The detector's 3D keypoints in this camera's frame (x right, y down, z
  // forward), millimetres up to scale; NaN = missing. If the wrist has a
  // plausible absolute depth (z > 0) the ray to the camera uses it, otherwise
  // the optical axis.
  HandPointsMm points_in_camera_mm;
  double confidence = 1.0;  // detector confidence in [0, 1]
};

struct HandFusionOptions {
  double min_confidence = 0.05;  // views below are ignored
  double view_angle_power = 1.0;
  double view_angle_floor = 0.05;  // floor of |cos| so an edge-on view never weighs 0
  bool normalise_scale = true;     // rescale each view's hand to the model's size
  Status Validate() const;
};

struct FusedHand {
  bool ok = false;
  std::string problem;
  HandPose pose;                        // wrist at the origin; angles within limits
  std::vector<double> view_weights;     // normalised to sum 1; 0 for unused views
  std::vector<double> view_fit_rms_mm;  // model fit residual per view (NaN unused)
  int num_views_used = 0;
};

// Throws std::invalid_argument on size mismatch or invalid options.
FusedHand FuseViewHands(const HandModel& model,
                        const std::vector<Camera>& cameras,
                        const std::vector<ViewHand3d>& views,
                        const HandFusionOptions& options);

// Projects a rotation onto a joint's axes: the angle about `axis` (1 dof) or
// (flex, abd) with R ~= R(a_abd, abd) R(a_flex, flex) (2 dofs, perpendicular
// axes); exact when R lies on the joint's manifold.
double AngleAboutAxis(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& axis);
void DecomposeUniversalJoint(const Eigen::Matrix3d& rotation,
                             const Eigen::Vector3d& flex_axis,
                             const Eigen::Vector3d& abd_axis,
                             double* flex,
                             double* abd);

}  // namespace arco::hand
