#include "arco/camera/camera.h"

#include "arco/camera/undistort.h"

namespace arco {

Eigen::Matrix3d Camera::K() const {
  Eigen::Matrix3d k;
  k << fx, skew, cx, 0, fy, cy, 0, 0, 1;
  return k;
}

std::array<double, kNumIntrinsics> Camera::Intrinsics() const {
  std::array<double, kNumIntrinsics> i{};
  i[kFx] = fx;
  i[kFy] = fy;
  i[kCx] = cx;
  i[kCy] = cy;
  i[kSkew] = skew;
  i[kK1] = distortion.k1;
  i[kK2] = distortion.k2;
  i[kK3] = distortion.k3;
  i[kP1] = distortion.p1;
  i[kP2] = distortion.p2;
  return i;
}

void Camera::SetIntrinsics(const std::array<double, kNumIntrinsics>& i) {
  fx = i[kFx];
  fy = i[kFy];
  cx = i[kCx];
  cy = i[kCy];
  skew = i[kSkew];
  distortion.k1 = i[kK1];
  distortion.k2 = i[kK2];
  distortion.k3 = i[kK3];
  distortion.p1 = i[kP1];
  distortion.p2 = i[kP2];
}

Eigen::Matrix<double, 3, 4> Camera::ProjectionMatrix() const {
  Eigen::Matrix<double, 3, 4> rt;
  rt.leftCols<3>() = cam_from_world.rotation;
  rt.col(3) = cam_from_world.translation;
  return K() * rt;
}

Eigen::Vector3d Camera::CenterInWorld() const {
  return -cam_from_world.rotation.transpose() * cam_from_world.translation;
}

Eigen::Vector3d Camera::PointInCamera(const Eigen::Vector3d& point_in_world) const {
  return cam_from_world * point_in_world;
}

bool Camera::ProjectWithJacobian(const Eigen::Vector3d& point_in_world,
                                 Eigen::Vector2d* pixel,
                                 Eigen::Matrix<double, 2, 3>* d_pixel_d_point) const {
  // Values in ProjectToPixel's order of operations, so the pixel is identical.
  double p[3];
  for (int r = 0; r < 3; ++r) {
    p[r] = cam_from_world.translation[r];
    for (int c = 0; c < 3; ++c) p[r] += cam_from_world.rotation(r, c) * point_in_world[c];
  }
  if (!(p[2] > 0)) return false;
  const double x = p[0] / p[2], y = p[1] / p[2];
  double xd, yd;
  Eigen::Matrix2d dist;  // d(xd, yd) / d(x, y)
  DistortWithJacobian(distortion, x, y, &xd, &yd, &dist);
  (*pixel)[0] = fx * xd + skew * yd + cx;
  (*pixel)[1] = fy * yd + cy;
  Eigen::Matrix2d k;
  k << fx, skew, 0.0, fy;
  const double iz = 1.0 / p[2];
  Eigen::Matrix<double, 2, 3> normalise;  // d(x, y) / d(point in camera)
  normalise << iz, 0.0, -x * iz, 0.0, iz, -y * iz;
  *d_pixel_d_point = (k * dist) * normalise * cam_from_world.rotation;
  return true;
}

std::optional<Eigen::Vector2d> Camera::Project(const Eigen::Vector3d& point_in_world) const {
  Eigen::Vector2d pixel;
  if (!ProjectToPixel(point_in_world.data(), pixel.data())) return std::nullopt;
  return pixel;
}

Eigen::Vector2d Camera::PixelToNormalized(const Eigen::Vector2d& pixel) const {
  // Distorted normalised coordinates from the inverse of K.
  const double yd = (pixel.y() - cy) / fy;
  const double xd = (pixel.x() - cx - skew * yd) / fx;
  if (distortion.IsZero()) return {xd, yd};
  // Gauss-Newton on f(x, y) = distort(x, y) - (xd, yd), numeric 2x2 Jacobian.
  Eigen::Vector2d est(xd, yd);
  for (int iter = 0; iter < 20; ++iter) {
    double fx0, fy0;
    Distort(est.x(), est.y(), &fx0, &fy0);
    const Eigen::Vector2d residual(fx0 - xd, fy0 - yd);
    if (residual.squaredNorm() < 1e-24) break;
    const double h = 1e-7;
    double ax, ay, bx, by;
    Distort(est.x() + h, est.y(), &ax, &ay);
    Distort(est.x(), est.y() + h, &bx, &by);
    Eigen::Matrix2d jac;
    jac << (ax - fx0) / h, (bx - fx0) / h, (ay - fy0) / h, (by - fy0) / h;
    const Eigen::Vector2d step = jac.partialPivLu().solve(residual);
    if (!step.allFinite()) break;
    est -= step;
  }
  return est;
}

Eigen::Vector2d Camera::UndistortPixel(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d n = PixelToNormalized(pixel);
  return {fx * n.x() + skew * n.y() + cx, fy * n.y() + cy};
}

Eigen::Vector3d Camera::RayInWorld(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d n = PixelToNormalized(pixel);
  return (cam_from_world.rotation.transpose() * Eigen::Vector3d(n.x(), n.y(), 1.0)).normalized();
}

}  // namespace arco
