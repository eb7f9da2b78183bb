#include "arco/mocap/refine_point.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "arco/geometry/triangulation.h"
#include "arco/mocap/refine_point_pixels.h"

namespace arco {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The robust problem linearised at one point.
struct Linearization {
  double cost = kInf;  // sum |r_i'|^2, px^2
  Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
  Eigen::Vector3d jtr = Eigen::Vector3d::Zero();
  Eigen::Vector2d* pixels = nullptr;  // each view's pixel at the point, when not null
};

// Robustified residual r' = s(|r|^2) r with s = sqrt(rho(|r|^2) / |r|^2)
// = sqrt(2 / (1 + q)), q = sqrt(1 + |r|^2 / b^2), so |r'|^2 = rho(|r|^2) and minimising
// sum |r'|^2 minimises the robust cost (the scaling is smooth at r = 0). Its Jacobian
// J' = (s I + 2 (ds/d|r|^2) r r^T) J with ds/d|r|^2 = -s^3 / (8 b^2 q) and
// J = sqrt(weight) d pixel / d point: a 2x2 matrix M w applied to the pixel Jacobian,
// and only the upper triangle of the symmetric J'^T J' is summed.
// False when the point is behind a view.
bool Linearize(const RefinementView* views,
               int count,
               double inv_b2,
               const Eigen::Vector3d& x,
               Linearization* out) {
  double cost = 0;
  // Upper triangle of J^T J (symmetric), filled in below.
  double h00 = 0, h01 = 0, h02 = 0, h11 = 0, h12 = 0, h22 = 0;
  Eigen::Vector3d jtr = Eigen::Vector3d::Zero();
  for (int i = 0; i < count; ++i) {
    const RefinementView& v = views[i];
    Eigen::Vector2d pixel;
    Eigen::Matrix<double, 2, 3> d_pixel;
    if (!v.camera->ProjectWithJacobian(x, &pixel, &d_pixel)) return false;
    if (out->pixels != nullptr) out->pixels[i] = pixel;
    const double w = v.sqrt_weight;
    const double rx = w * (pixel.x() - v.pixel.x()), ry = w * (pixel.y() - v.pixel.y());
    const double q = std::sqrt(1 + (rx * rx + ry * ry) * inv_b2);
    const double s = std::sqrt(2 / (1 + q));
    const double ds2 = -s * s * s * inv_b2 / (4 * q);  // 2 ds/d|r|^2
    // M w, with M = s I + ds2 r r^T.
    const double m00 = w * (s + ds2 * rx * rx), m01 = w * (ds2 * rx * ry),
                 m11 = w * (s + ds2 * ry * ry);
    const Eigen::RowVector3d j0 = m00 * d_pixel.row(0) + m01 * d_pixel.row(1);
    const Eigen::RowVector3d j1 = m01 * d_pixel.row(0) + m11 * d_pixel.row(1);
    const double r0 = s * rx, r1 = s * ry;
    cost += r0 * r0 + r1 * r1;
    h00 += j0[0] * j0[0] + j1[0] * j1[0];
    h01 += j0[0] * j0[1] + j1[0] * j1[1];
    h02 += j0[0] * j0[2] + j1[0] * j1[2];
    h11 += j0[1] * j0[1] + j1[1] * j1[1];
    h12 += j0[1] * j0[2] + j1[1] * j1[2];
    h22 += j0[2] * j0[2] + j1[2] * j1[2];
    jtr += (r0 * j0 + r1 * j1).transpose();
  }
  out->cost = cost;
  out->jtj << h00, h01, h02, h01, h11, h12, h02, h12, h22;
  out->jtr = jtr;
  return true;
}

}  // namespace

Status PointRefinementOptions::Validate() const {
  auto bad = [](const char* m) { return Status::Error(std::string("point refinement: ") + m); };
  if (!(loss_scale_px > 0 && std::isfinite(loss_scale_px))) {
    return bad("loss_scale_px must be a positive number");
  }
  if (max_iterations < 1) return bad("max_iterations must be >= 1");
  if (!(parameter_tolerance >= 0) || !(function_tolerance_px2 >= 0)) {
    return bad("tolerances must be >= 0");
  }
  return Status::Ok();
}

namespace internal {

bool RefinePointRobustWithPixels(const RefinementView* views,
                                 int count,
                                 const PointRefinementOptions& options,
                                 Eigen::Vector3d* point_in_world,
                                 Eigen::Vector2d* pixels,
                                 PointRefinementSummary* summary_out) {
  const double inv_b2 = 1.0 / (options.loss_scale_px * options.loss_scale_px);
  PointRefinementSummary& summary = *summary_out;
  summary = PointRefinementSummary();
  Eigen::Vector3d& x = *point_in_world;
  Linearization at_x, trial;
  // Two halves of the scratch, swapped with the linearisations: at_x's pixels are always
  // those at x.
  if (pixels != nullptr) at_x.pixels = pixels, trial.pixels = pixels + count;
  ++summary.evaluations;
  if (!Linearize(views, count, inv_b2, x, &at_x)) {
    summary.initial_cost = summary.final_cost = kInf;
    return false;
  }
  summary.initial_cost = summary.final_cost = at_x.cost;
  // Levenberg-Marquardt with Marquardt's scaling, (J^T J + mu diag(J^T J)) dx = -J^T r,
  // and Nielsen's damping update (Madsen, Nielsen & Tingleff 2004, "Methods for
  // non-linear least squares problems", sec. 3.2): a good step shrinks mu by up to 3,
  // a rejected one grows it geometrically. The DLT start is close to the minimum, so
  // mu starts small and the first steps are nearly Gauss-Newton.
  double mu = 1e-4, nu = 2;
  for (int iter = 0; iter < options.max_iterations; ++iter) {
    ++summary.iterations;
    Eigen::Matrix3d a = at_x.jtj;
    for (int k = 0; k < 3; ++k) a(k, k) += mu * std::max(at_x.jtj(k, k), 1e-12);
    const std::optional<Eigen::Vector3d> step = SolveSymmetric3x3(a, -at_x.jtr);
    if (!step) break;
    const Eigen::Vector3d& dx = *step;
    if (dx.norm() <= options.parameter_tolerance * (x.norm() + options.parameter_tolerance)) break;
    // Decrease the linearised model predicts, -2 dx^T J^T r - dx^T J^T J dx: when even
    // the model promises less than the tolerance, evaluating the step is not worth it.
    const double predicted = -dx.dot(2 * at_x.jtr + at_x.jtj * dx);
    if (predicted < options.function_tolerance_px2) break;
    const Eigen::Vector3d x_new = x + dx;
    ++summary.evaluations;
    const bool in_front = Linearize(views, count, inv_b2, x_new, &trial);
    const double actual = at_x.cost - trial.cost;
    if (in_front && actual > 0) {
      x = x_new;
      std::swap(at_x, trial);
      const double rho = actual / predicted;
      const double t = 2 * rho - 1;
      mu *= std::max(1.0 / 3.0, 1 - t * t * t);
      nu = 2;
      if (actual < options.function_tolerance_px2) break;
    } else {
      mu *= nu;
      nu *= 2;
    }
  }
  summary.final_cost = at_x.cost;
  if (pixels != nullptr && at_x.pixels != pixels)
    std::copy(at_x.pixels, at_x.pixels + count, pixels);
  return true;
}

}  // namespace internal

PointRefinementSummary RefinePointRobust(const RefinementView* views,
                                         int count,
                                         const PointRefinementOptions& options,
                                         Eigen::Vector3d* point_in_world) {
  PointRefinementSummary summary;
  internal::RefinePointRobustWithPixels(views, count, options, point_in_world, nullptr, &summary);
  return summary;
}

}  // namespace arco
