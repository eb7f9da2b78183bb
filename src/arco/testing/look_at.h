// The look-at camera of the synthetic rigs in tests and benchmarks: one definition of the
// rotation every generated rig (rings, arcs, board rigs, plane scenes) is built from.
//
// Convention (camera.h): rows of cam_from_world are the camera's x (image right), y (image
// down) and z (viewing direction) axes in world coordinates. z points from the centre to
// the target, x = z x up (normalised) and y = z x x, so image y runs against `up_in_world`
// (with up = world z, an upright camera). `up_in_world` must not be parallel to the
// viewing direction.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace arco::testing {

// The rotation of a camera at `center_in_world` looking at `target_in_world`.
inline Eigen::Matrix3d CamFromWorldLookingAt(
    const Eigen::Vector3d& center_in_world,
    const Eigen::Vector3d& target_in_world,
    const Eigen::Vector3d& up_in_world = Eigen::Vector3d::UnitZ()) {
  const Eigen::Vector3d z = (target_in_world - center_in_world).normalized();
  const Eigen::Vector3d x = z.cross(up_in_world).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d cam_from_world;
  cam_from_world.row(0) = x;
  cam_from_world.row(1) = y;
  cam_from_world.row(2) = z;
  return cam_from_world;
}

}  // namespace arco::testing
