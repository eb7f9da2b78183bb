// Pinhole camera with Brown-Conrady distortion, in OpenCV's conventions:
//   x_cam = R * X_world + t                       (cam_from_world)
//   x = X/Z, y = Y/Z, r2 = x^2 + y^2
//   x' = x (1 + k1 r2 + k2 r2^2 + k3 r2^3) + 2 p1 x y + p2 (r2 + 2 x^2)
//   y' = y (1 + k1 r2 + k2 r2^2 + k3 r2^3) + p1 (r2 + 2 y^2) + 2 p2 x y
//   u = fx x' + skew y' + cx,   v = fy y' + cy
// Pixel coordinates put the origin at the CENTRE of the top-left pixel (OpenCV).
// Metashape puts it at the corner and swaps the roles of p1/p2; the readers in
// calibration_io.h convert (u_opencv = u_metashape - 0.5, p1 <-> p2).
// Units of t (and of world points) are those of the calibration (Rig::units).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "arco/geometry/transform.h"

namespace arco {

// The intrinsics as one parameter block, for solvers that refine them (arco calibrate's
// bundle adjustment): the model below is written once, in PixelFromPointInCamera.
enum IntrinsicIndex : int { kFx, kFy, kCx, kCy, kSkew, kK1, kK2, kK3, kP1, kP2, kNumIntrinsics };

// Brown-Conrady distortion of normalised coordinates (x, y) -> (x', y') with the
// distortion entries of an intrinsics block (kK1..kP2); templated for autodiff.
template <typename T>
void DistortNormalized(const T* intrinsics, const T& x, const T& y, T* xd, T* yd) {
  const T& k1 = intrinsics[kK1];
  const T& k2 = intrinsics[kK2];
  const T& k3 = intrinsics[kK3];
  const T& p1 = intrinsics[kP1];
  const T& p2 = intrinsics[kP2];
  const T r2 = x * x + y * y;
  const T radial = T(1) + r2 * (k1 + r2 * (k2 + r2 * k3));
  *xd = x * radial + T(2) * p1 * x * y + p2 * (r2 + T(2) * x * x);
  *yd = y * radial + p1 * (r2 + T(2) * y * y) + T(2) * p2 * x * y;
}

// Pixel of a point in the camera frame; false when it is not in front (z <= 0).
template <typename T>
bool PixelFromPointInCamera(const T* intrinsics, const T* point_in_camera, T* pixel) {
  if (!(point_in_camera[2] > T(0))) return false;
  const T x = point_in_camera[0] / point_in_camera[2];
  const T y = point_in_camera[1] / point_in_camera[2];
  T xd, yd;
  DistortNormalized(intrinsics, x, y, &xd, &yd);
  pixel[0] = intrinsics[kFx] * xd + intrinsics[kSkew] * yd + intrinsics[kCx];
  pixel[1] = intrinsics[kFy] * yd + intrinsics[kCy];
  return true;
}

struct Distortion {
  double k1 = 0, k2 = 0, k3 = 0;  // radial
  double p1 = 0, p2 = 0;          // tangential, OpenCV roles
  bool IsZero() const { return k1 == 0 && k2 == 0 && k3 == 0 && p1 == 0 && p2 == 0; }
};

struct Camera {
  std::string name;    // e.g. "cam0" or "camera_21334181_1"
  std::string serial;  // e.g. "21334181"; empty when unknown
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0, skew = 0;
  Distortion distortion;
  RigidMatrix3d cam_from_world;  // x_cam = R X_world + t (mm or the calibration's units)

  Eigen::Matrix3d K() const;
  // fx fy cx cy skew k1 k2 k3 p1 p2 (IntrinsicIndex order), and back.
  std::array<double, kNumIntrinsics> Intrinsics() const;
  void SetIntrinsics(const std::array<double, kNumIntrinsics>& intrinsics);
  // 3x4 P = K [R | t] (no distortion): for DLT on undistorted pixels.
  Eigen::Matrix<double, 3, 4> ProjectionMatrix() const;
  Eigen::Vector3d CenterInWorld() const;
  Eigen::Vector3d PointInCamera(const Eigen::Vector3d& point_in_world) const;

  // Distortion of normalised coordinates (x, y) -> (x', y'); templated for Ceres.
  template <typename T>
  void Distort(const T& x, const T& y, T* xd, T* yd) const;

  // Projects a world point to pixels with distortion; templated for autodiff.
  // Returns false when the point is not in front of the camera (z <= 0).
  template <typename T>
  bool ProjectToPixel(const T* point_in_world, T* pixel) const;

  // ProjectToPixel<double> (the same pixel, bit for bit) and its 2x3 derivative with
  // respect to the world point in closed form (chain rule through K, the Brown-Conrady
  // distortion, x = X/Z, y = Y/Z and R): about a third of the cost of ceres::Jet<3>.
  bool ProjectWithJacobian(const Eigen::Vector3d& point_in_world,
                           Eigen::Vector2d* pixel,
                           Eigen::Matrix<double, 2, 3>* d_pixel_d_point) const;

  // Convenience: nullopt when behind the camera.
  std::optional<Eigen::Vector2d> Project(const Eigen::Vector3d& point_in_world) const;

  // Removes distortion: pixel -> normalised image coordinates (x, y) with
  // X/Z = x, Y/Z = y. Iterative (Gauss-Newton on the forward model).
  Eigen::Vector2d PixelToNormalized(const Eigen::Vector2d& pixel) const;
  // Removes distortion but stays in pixels (ideal pinhole pixel with the same K).
  Eigen::Vector2d UndistortPixel(const Eigen::Vector2d& pixel) const;
  // Unit viewing ray through a pixel, in world coordinates.
  Eigen::Vector3d RayInWorld(const Eigen::Vector2d& pixel) const;
};

template <typename T>
void Camera::Distort(const T& x, const T& y, T* xd, T* yd) const {
  const std::array<double, kNumIntrinsics> d = Intrinsics();
  T intrinsics[kNumIntrinsics];
  for (int i = 0; i < kNumIntrinsics; ++i) intrinsics[i] = T(d[i]);
  DistortNormalized(intrinsics, x, y, xd, yd);
}

template <typename T>
bool Camera::ProjectToPixel(const T* point_in_world, T* pixel) const {
  T p[3];
  for (int r = 0; r < 3; ++r) {
    p[r] = T(cam_from_world.translation[r]);
    for (int c = 0; c < 3; ++c) p[r] += T(cam_from_world.rotation(r, c)) * point_in_world[c];
  }
  const std::array<double, kNumIntrinsics> d = Intrinsics();
  T intrinsics[kNumIntrinsics];
  for (int i = 0; i < kNumIntrinsics; ++i) intrinsics[i] = T(d[i]);
  return PixelFromPointInCamera(intrinsics, p, pixel);
}

}  // namespace arco
