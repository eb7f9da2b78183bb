// The reprojection residual every calibration bundle adjustment uses (arco calibrate's
// board rig, arco calibrate refine's performer and instrument): a pose is 6 parameters,
// an angle-axis rotation then a translation, x' = R(pose[0..2]) x + pose[3..5]; a point in
// world coordinates goes through the camera's pose and the camera model written once in
// camera.h (PixelFromPointInCamera, distortion included). Templated for Ceres' autodiff;
// include only from code that links Ceres.
#pragma once

#include <ceres/rotation.h>

#include <Eigen/Core>

#include "arco/camera/camera.h"

namespace arco::calibration {

// out = R(pose[0..2]) * point + pose[3..5].
template <typename T>
void TransformByPose(const T* pose, const T* point, T* out) {
  ceres::AngleAxisRotatePoint(pose, point, out);
  for (int i = 0; i < 3; ++i) out[i] += pose[3 + i];
}

// residual = pixel(intrinsics, cam_from_world * world_point) - observed_px; false (the
// residual not evaluated) when the point is not in front of the camera.
template <typename T>
bool ReprojectionResidual(const T* cam_from_world,
                          const T* intrinsics,
                          const T* world_point,
                          const Eigen::Vector2d& observed_px,
                          T* residual) {
  T camera_point[3];
  TransformByPose(cam_from_world, world_point, camera_point);
  T pixel[2];
  if (!PixelFromPointInCamera(intrinsics, camera_point, pixel)) return false;
  residual[0] = pixel[0] - T(observed_px.x());
  residual[1] = pixel[1] - T(observed_px.y());
  return true;
}

}  // namespace arco::calibration
