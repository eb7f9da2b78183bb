#include "arco/mocap/refine_point.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

namespace arco {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The robust problem linearised at one point.
struct Linearization {
  double cost = kInf;  // sum |r_i'|^2, px^2
  Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
  Eigen::Vector3d jtr = Eigen::Vector3d::Zero();
};

// Robustified residual r' = s(|r|^2) r with s = sqrt(rho(|r|^2) / |r|^2)
// = sqrt(2 / (1 + q)), q = sqrt(1 + |r|^2 / b^2), so |r'|^2 = rho(|r|^2) and minimising
// sum |r'|^2 minimises the robust cost (the scaling is smooth at r = 0). Its Jacobian
// J' = s J + r (ds/d|r|^2) 2 r^T J with ds/d|r|^2 = -s^3 / (8 b^2 q).
// False when the point is behind a view.
bool Linearize(const RefinementView* views,
               int count,
               double inv_b2,
               const Eigen::Vector3d& x,
               Linearization* out) {
  double cost = 0;
  Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
  Eigen::Vector3d jtr = Eigen::Vector3d::Zero();
  for (int i = 0; i < count; ++i) {
    const RefinementView& v = views[i];
    Eigen::Vector2d pixel;
    Eigen::Matrix<double, 2, 3> d_pixel;
    if (!v.camera->ProjectWithJacobian(x, &pixel, &d_pixel)) return false;
    const Eigen::Vector2d r = v.sqrt_weight * (pixel - v.pixel);
    const Eigen::Matrix<double, 2, 3> dr = v.sqrt_weight * d_pixel;
    const double q = std::sqrt(1 + r.squaredNorm() * inv_b2);
    const double s = std::sqrt(2 / (1 + q));
    const double ds = -s * s * s * inv_b2 / (8 * q);
    const Eigen::Matrix<double, 2, 3> j = s * dr + (2 * ds) * r * (r.transpose() * dr);
    const Eigen::Vector2d rs = s * r;
    cost += rs.squaredNorm();
    jtj.noalias() += j.transpose() * j;
    jtr.noalias() += j.transpose() * rs;
  }
  out->cost = cost;
  out->jtj = jtj;
  out->jtr = jtr;
  return true;
}

}  // namespace

PointRefinementSummary RefinePointRobust(const RefinementView* views,
                                         int count,
                                         const PointRefinementOptions& options,
                                         Eigen::Vector3d* point_in_world) {
  const double inv_b2 = 1.0 / (options.loss_scale_px * options.loss_scale_px);
  PointRefinementSummary summary;
  Eigen::Vector3d& x = *point_in_world;
  Linearization at_x, trial;
  ++summary.evaluations;
  if (!Linearize(views, count, inv_b2, x, &at_x)) {
    summary.initial_cost = summary.final_cost = kInf;
    return summary;
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
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(a);
    const Eigen::Vector3d dx = ldlt.solve(-at_x.jtr);
    if (ldlt.info() != Eigen::Success || !dx.allFinite()) break;
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
  return summary;
}

}  // namespace arco
