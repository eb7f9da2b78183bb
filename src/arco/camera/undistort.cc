#include "arco/camera/undistort.h"

#include <cmath>

namespace arco {

Eigen::Vector2d PixelToNormalizedNewton(const Camera& camera, const Eigen::Vector2d& pixel) {
  const double yd = (pixel.y() - camera.cy) / camera.fy;
  const double xd = (pixel.x() - camera.cx - camera.skew * yd) / camera.fx;
  if (camera.distortion.IsZero()) return {xd, yd};
  // Newton on f(x, y) = distort(x, y) - (xd, yd): (x, y) -= J^-1 f, with the 2x2
  // inverse written out (J is close to the identity for real lenses).
  double x = xd, y = yd;
  for (int iter = 0; iter < 20; ++iter) {
    double fx0, fy0;
    Eigen::Matrix2d j;
    DistortWithJacobian(camera.distortion, x, y, &fx0, &fy0, &j);
    const double rx = fx0 - xd, ry = fy0 - yd;
    if (rx * rx + ry * ry < 1e-24) break;
    const double det = j(0, 0) * j(1, 1) - j(0, 1) * j(1, 0);
    const double step_x = (j(1, 1) * rx - j(0, 1) * ry) / det;
    const double step_y = (j(0, 0) * ry - j(1, 0) * rx) / det;
    if (!std::isfinite(step_x) || !std::isfinite(step_y)) break;
    x -= step_x;
    y -= step_y;
  }
  return {x, y};
}

}  // namespace arco
