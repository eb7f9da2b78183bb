// Residuals of the hand fits (internal to arco_hand), the problems the fits solve with
// util/dense_lm.h (HandProblem) and the Ceres cost function of the same residuals
// (HandCostFunction, the tests' reference). All take the parameters {wrist angle-axis (3),
// wrist position mm (3), angles (20)} and run forward kinematics once per evaluation for
// all their residuals.
//
// Robust losses are applied inside the residual ("square-root of rho"):
// r' = sqrt(rho(|r|^2) / |r|^2) r, so that sum |r'|^2 = sum rho(|r_i|^2) with a
// loss per keypoint while FK runs once for the whole block. Its exact Jacobian
// keeps Gauss-Newton consistent with the robust cost (same minimisers).
#pragma once

#include <ceres/jet.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <vector>

#include "arco/camera/camera.h"
#include "arco/hand/kinematics.h"

namespace arco::hand::internal {

// GCC leaves the small Jet operations of the projection's derivative out of line (about
// a third of the fit's time in calls); flatten inlines them into the hot functions. The
// same operations run in the same order, so results are unchanged bit for bit.
#if defined(__GNUC__) && !defined(__clang__)
#define ARCO_FLATTEN __attribute__((flatten))
#else
#define ARCO_FLATTEN
#endif

// sqrt(rho(s) / s) for the Cauchy loss rho(s) = c2 log(1 + s / c2).
template <typename T>
T CauchyScale(const T& s, double c2) {
  using std::log;
  using std::sqrt;
  if (s < T(1e-9 * c2)) return T(1) - s / T(4 * c2);  // series, smooth at 0
  return sqrt(T(c2) * log(T(1) + s / T(c2)) / s);
}

struct PixelObservation {
  const Camera* camera = nullptr;
  int view = 0;
  int keypoint = 0;
  Eigen::Vector2d pixel;
  double sqrt_weight = 1.0;
};

struct ReprojectionResiduals {
  const HandModel* model;
  const std::vector<PixelObservation>* observations;
  double loss_c2;  // squared Cauchy scale, px^2

  static constexpr int kRowsPerUnit = 2;  // per observation
  int num_units() const { return static_cast<int>(observations->size()); }
  int num_residuals() const { return 2 * num_units(); }
  template <typename T>
  void operator()(const T* aa, const T* t, const T* angles, T* residuals) const {
    Eigen::Matrix<T, 3, 1> points[kNumHandKeypoints];
    HandPointsInWorld(*model, aa, t, angles, points);
    for (size_t i = 0; i < observations->size(); ++i) {
      const PixelObservation& o = (*observations)[i];
      T pixel[2];
      T* r = residuals + 2 * i;
      if (!o.camera->ProjectToPixel(points[o.keypoint].data(), pixel)) {
        // Behind the camera: a constant, saturated outlier residual.
        r[0] = T(o.sqrt_weight * 10.0 * std::sqrt(loss_c2));
        r[1] = T(0);
        continue;
      }
      r[0] = pixel[0] - T(o.pixel.x());
      r[1] = pixel[1] - T(o.pixel.y());
      const T scale = T(o.sqrt_weight) * CauchyScale(r[0] * r[0] + r[1] * r[1], loss_c2);
      r[0] *= scale;
      r[1] *= scale;
    }
  }
  // Observation i: its 2 residuals and their derivative w.r.t. its keypoint, in closed
  // form: r = w (pixel - observed), r' = c(s) r with s = |r|^2 and the Cauchy scale
  // c(s) = sqrt(c2 log(1 + s / c2) / s), dc/ds = (1 / (s (1 + s / c2)) - c^2 / s) / (2 c)
  // (-1 / (4 c2) on CauchyScale's series branch), so dr'/dp = c dr/dp + r dc/ds 2 r^T dr/dp.
  int ResidualWithDerivative(int i,
                             const Eigen::Vector3d* points,
                             double* residual,
                             Eigen::Matrix3d* d_residual,
                             int* keypoint) const {
    const PixelObservation& o = (*observations)[i];
    *keypoint = o.keypoint;
    d_residual->setZero();
    Eigen::Vector2d pixel;
    Eigen::Matrix<double, 2, 3> d_pixel;
    if (!o.camera->ProjectWithJacobian(points[o.keypoint], &pixel, &d_pixel)) {
      residual[0] = o.sqrt_weight * 10.0 * std::sqrt(loss_c2);
      residual[1] = 0.0;
      return 2;
    }
    const Eigen::Vector2d r = pixel - o.pixel;
    const double s = r.squaredNorm();
    const double c = CauchyScale(s, loss_c2);
    const double dc_ds = s < 1e-9 * loss_c2
                             ? -1.0 / (4 * loss_c2)
                             : (1.0 / (s * (1.0 + s / loss_c2)) - c * c / s) / (2 * c);
    const Eigen::RowVector3d ds = 2.0 * r.transpose() * d_pixel;
    const Eigen::Matrix<double, 2, 3> d = o.sqrt_weight * (c * d_pixel + r * (dc_ds * ds));
    d_residual->topRows<2>() = d;
    residual[0] = o.sqrt_weight * c * r[0];
    residual[1] = o.sqrt_weight * c * r[1];
    return 2;
  }
};

struct PointResiduals {
  const HandModel* model;
  const HandPointsMm* targets;  // NaN = missing (zero residual)
  double loss_c2;               // squared Cauchy scale, mm^2

  static constexpr int kRowsPerUnit = 3;  // per keypoint
  int num_units() const { return kNumHandKeypoints; }
  int num_residuals() const { return 3 * kNumHandKeypoints; }
  template <typename T>
  void operator()(const T* aa, const T* t, const T* angles, T* residuals) const {
    Eigen::Matrix<T, 3, 1> points[kNumHandKeypoints];
    HandPointsInWorld(*model, aa, t, angles, points);
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      T* r = residuals + 3 * k;
      if (!(*targets)[k].allFinite()) {
        r[0] = r[1] = r[2] = T(0);
        continue;
      }
      for (int c = 0; c < 3; ++c) r[c] = points[k][c] - T((*targets)[k][c]);
      const T scale = CauchyScale(r[0] * r[0] + r[1] * r[1] + r[2] * r[2], loss_c2);
      for (int c = 0; c < 3; ++c) r[c] *= scale;
    }
  }
  // Keypoint i: its 3 residuals (0 when missing) and their derivative.
  ARCO_FLATTEN int ResidualWithDerivative(int i,
                                          const Eigen::Vector3d* points,
                                          double* residual,
                                          Eigen::Matrix3d* d_residual,
                                          int* keypoint) const {
    using Jet3 = ceres::Jet<double, 3>;
    *keypoint = i;
    if (!(*targets)[i].allFinite()) {
      residual[0] = residual[1] = residual[2] = 0;
      d_residual->setZero();
      return 3;
    }
    Jet3 r[3];
    for (int c = 0; c < 3; ++c) r[c] = Jet3(points[i][c] - (*targets)[i][c], c);
    const Jet3 scale = CauchyScale(r[0] * r[0] + r[1] * r[1] + r[2] * r[2], loss_c2);
    for (int c = 0; c < 3; ++c) {
      r[c] *= scale;
      residual[c] = r[c].a;
      d_residual->row(c) = r[c].v.transpose();
    }
    return 3;
  }
};

// Temporal prior: rotation difference (vee of the skew part of R_prev^T R),
// translation difference and angle differences, each weighted.
struct TemporalResiduals {
  Eigen::Matrix3d previous_rotation;
  Eigen::Vector3d previous_translation;
  std::array<double, kNumJointDofs> previous_angles;
  double w_rotation, w_translation, w_angle;

  template <typename T>
  bool operator()(const T* aa, const T* t, const T* angles, T* r) const {
    const Eigen::Matrix<T, 3, 3> m =
        previous_rotation.transpose().cast<T>() * AngleAxisToMatrix(aa);
    r[0] = T(0.5 * w_rotation) * (m(2, 1) - m(1, 2));
    r[1] = T(0.5 * w_rotation) * (m(0, 2) - m(2, 0));
    r[2] = T(0.5 * w_rotation) * (m(1, 0) - m(0, 1));
    for (int c = 0; c < 3; ++c) r[3 + c] = T(w_translation) * (t[c] - T(previous_translation[c]));
    for (int d = 0; d < kNumJointDofs; ++d)
      r[6 + d] = T(w_angle) * (angles[d] - T(previous_angles[d]));
    return true;
  }
};

// A hand fit as a problem for DenseLm (util/dense_lm.h): parameters x = (wrist
// angle-axis, wrist position mm, 20 angles), cost 1/2 |r|^2 over the residuals of
// HandCostFunction<Residuals> (ReprojectionResiduals: 2 per observation, 840 for 20
// views; PointResiduals: 3 per keypoint) and, with a previous frame, TemporalResiduals.
// Levenberg-Marquardt uses the residuals r and Jacobian J only through the cost, J^T J and
// J^T r, so those are summed per keypoint, J_k^T (sum_o D_o^T D_o) J_k with D_o the
// derivative of unit o (2x3 or 3x3) and J_k the keypoint's 3x26 Jacobian: no 840-row
// matrix is formed. Locked joints (min == max) are held (their rows and columns of J^T J
// and J^T r are 0, so their step is 0), the others are kept within their limits by
// projecting each step (as Ceres does with bounds). Until issue 28 part 3 these were
// ceres::Problems (the reprojection block compressed to 27 residuals of the same normal
// equations, an LDLT per evaluation), which evaluated the cost a second time for each
// accepted step.
template <typename Residuals>
class HandProblem {
 public:
  static constexpr int kParams = 6 + kNumJointDofs;
  using Vector = Eigen::Matrix<double, kParams, 1>;
  using Matrix = Eigen::Matrix<double, kParams, kParams>;

  // `temporal`: nullptr for none.
  HandProblem(Residuals residuals, const TemporalResiduals* temporal)
      : r_(residuals), temporal_(temporal) {
    for (int d = 0; d < kNumJointDofs; ++d)
      locked_[d] = r_.model->max_rad(d) - r_.model->min_rad(d) < 1e-12;
  }

  ARCO_FLATTEN double Evaluate(const Vector& x, Matrix* h, Vector* g) const {
    Eigen::Vector3d points[kNumHandKeypoints];
    HandPointJacobian point_jacobians[kNumHandKeypoints];
    HandPointsAndJacobians(
        *r_.model, x.data(), x.data() + 3, x.data() + 6, points, point_jacobians);
    Eigen::Matrix3d hk[kNumHandKeypoints];  // sum of D^T D per keypoint
    Eigen::Vector3d gk[kNumHandKeypoints];  // sum of D^T r per keypoint
    bool seen[kNumHandKeypoints] = {};
    for (int k = 0; k < kNumHandKeypoints; ++k) hk[k].setZero(), gk[k].setZero();
    double rr = 0;
    constexpr int kRows = Residuals::kRowsPerUnit;
    const int n = r_.num_units();
    for (int i = 0; i < n; ++i) {
      Eigen::Matrix3d d;
      double r[3];
      int k;
      r_.ResidualWithDerivative(i, points, r, &d, &k);
      const Eigen::Matrix<double, kRows, 3> dr = d.topRows<kRows>();
      const Eigen::Matrix<double, kRows, 1> rv = Eigen::Map<Eigen::Matrix<double, kRows, 1>>(r);
      hk[k].noalias() += dr.transpose() * dr;
      gk[k].noalias() += dr.transpose() * rv;
      rr += rv.squaredNorm();
      seen[k] = true;
    }
    Matrix& jtj = *h;
    Vector& jtr = *g;
    jtj.setZero();
    jtr.setZero();
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      if (!seen[k]) continue;
      const HandPointJacobian& jk = point_jacobians[k];
      // Coefficient-wise products: at these fixed sizes Eigen's default (a blocked GEMM
      // with packing) spent more time in copies than in arithmetic.
      const Eigen::Matrix<double, kParams, 3> jh = jk.transpose().lazyProduct(hk[k]);
      // Only the lower triangle and only the columns the keypoint moves with
      // (HandPointsAndJacobians leaves the rest exactly 0): the wrist's translation, and
      // for a finger's keypoint the wrist's rotation and the finger's 4 angles. The terms
      // left out are exact zeros, at a twelfth of the products.
      int columns[10];
      int num_columns = 0;
      for (int c = k == 0 ? 3 : 0; c < 6; ++c) columns[num_columns++] = c;
      if (k > 0) {
        const int first = 6 + 4 * ((k - 1) / 4);
        for (int c = first; c < first + 4; ++c) columns[num_columns++] = c;
      }
      for (int b = 0; b < num_columns; ++b) {
        const int j = columns[b];
        const double j0 = jk(0, j), j1 = jk(1, j), j2 = jk(2, j);
        for (int a = b; a < num_columns; ++a) {
          const int i = columns[a];
          jtj(i, j) += (jh(i, 0) * j0 + jh(i, 1) * j1) + jh(i, 2) * j2;
        }
        jtr[j] += (j0 * gk[k][0] + j1 * gk[k][1]) + j2 * gk[k][2];
      }
    }
    if (temporal_ != nullptr) rr += AddTemporal(x, &jtj, &jtr);
    for (int d = 0; d < kNumJointDofs; ++d) {
      if (!locked_[d]) continue;
      jtj.row(6 + d).setZero();
      jtj.col(6 + d).setZero();
      jtr[6 + d] = 0;
    }
    jtj.triangularView<Eigen::StrictlyUpper>() = jtj.transpose();
    return 0.5 * rr;
  }

  // step = -a^-1 g (Cholesky: a is J^T J plus Marquardt's positive diagonal).
  bool SolveDamped(Matrix& a, const Vector& g, Vector* step) const {
    const Eigen::LLT<Matrix> llt(a);
    if (llt.info() != Eigen::Success) return false;
    *step = -llt.solve(g);
    return step->allFinite();
  }

  void Plus(const Vector& x, const Vector& step, Vector* candidate) const {
    *candidate = x + step;
    for (int d = 0; d < kNumJointDofs; ++d) {
      if (locked_[d]) continue;
      double& a = (*candidate)[6 + d];
      a = std::min(std::max(a, r_.model->min_rad(d)), r_.model->max_rad(d));
    }
  }

 private:
  // TemporalResiduals' |r|^2, added to J^T J (lower triangle) and J^T r: the rotation's 3
  // residuals depend on the angle-axis only (derivative from a 3-Jet), the others are
  // weighted differences of one parameter each.
  double AddTemporal(const Vector& x, Matrix* jtj, Vector* jtr) const {
    using Jet3 = ceres::Jet<double, 3>;
    const TemporalResiduals& p = *temporal_;
    const Jet3 aa[3] = {Jet3(x[0], 0), Jet3(x[1], 1), Jet3(x[2], 2)};
    const Eigen::Matrix<Jet3, 3, 3> m =
        p.previous_rotation.transpose().cast<Jet3>() * AngleAxisToMatrix(aa);
    const Jet3 rotation[3] = {Jet3(0.5 * p.w_rotation) * (m(2, 1) - m(1, 2)),
                              Jet3(0.5 * p.w_rotation) * (m(0, 2) - m(2, 0)),
                              Jet3(0.5 * p.w_rotation) * (m(1, 0) - m(0, 1))};
    double rr = 0;
    for (const Jet3& r : rotation) {
      rr += r.a * r.a;
      for (int j = 0; j < 3; ++j) {
        for (int i = j; i < 3; ++i) (*jtj)(i, j) += r.v[i] * r.v[j];
        (*jtr)[j] += r.v[j] * r.a;
      }
    }
    for (int c = 0; c < 3; ++c) {
      const double r = p.w_translation * (x[3 + c] - p.previous_translation[c]);
      rr += r * r;
      (*jtj)(3 + c, 3 + c) += p.w_translation * p.w_translation;
      (*jtr)[3 + c] += p.w_translation * r;
    }
    for (int d = 0; d < kNumJointDofs; ++d) {
      const double r = p.w_angle * (x[6 + d] - p.previous_angles[d]);
      rr += r * r;
      (*jtj)(6 + d, 6 + d) += p.w_angle * p.w_angle;
      (*jtr)[6 + d] += p.w_angle * r;
    }
    return rr;
  }

  Residuals r_;
  const TemporalResiduals* temporal_;
  bool locked_[kNumJointDofs];
};
using ReprojectionProblem = HandProblem<ReprojectionResiduals>;
using PointProblem = HandProblem<PointResiduals>;

}  // namespace arco::hand::internal
