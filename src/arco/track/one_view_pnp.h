// A rigid body's pose in ONE camera from its points' pixels: EPnP in RANSAC (OpenCV), the
// start that the callers refine (calibration from the instrument with OpenCV's iterative
// PnP; the one-camera lift, monocular_lift.h, on arco's camera model with distortion).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "arco/geometry/transform.h"

namespace arco::track {

struct OneViewPnp {
  Eigen::Vector3d angle_axis;   // cam_from_object's rotation (OpenCV's rvec)
  Eigen::Vector3d translation;  // cam_from_object's translation (tvec), the object's units
  RigidMatrix3d cam_from_object;
  std::vector<int> inliers;  // indices into the points given
};

// `pixels` are pinhole pixels (undistorted) of `object_points` under `K`; `gate_px` the
// RANSAC inlier gate. Empty when RANSAC fails or finds fewer than `min_inliers` inliers.
// The pose may put the body behind the camera: callers check. Repeatable (OpenCV seeds
// its RANSAC itself).
std::optional<OneViewPnp> EpnpInRansac(const std::vector<Eigen::Vector3d>& object_points,
                                       const std::vector<Eigen::Vector2d>& pixels,
                                       const Eigen::Matrix3d& K,
                                       double gate_px,
                                       int min_inliers);

}  // namespace arco::track
