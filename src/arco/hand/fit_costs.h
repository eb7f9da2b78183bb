// Ceres cost functions of the hand fits (internal to arco_hand). All take the
// parameter blocks {wrist angle-axis (3), wrist position mm (3), angles (20)}
// and run forward kinematics once per evaluation for all their residuals.
//
// Robust losses are applied inside the residual ("square-root of rho"):
// r' = sqrt(rho(|r|^2) / |r|^2) r, so that sum |r'|^2 = sum rho(|r_i|^2) with a
// loss per keypoint while FK runs once for the whole block. Its exact Jacobian
// keeps Gauss-Newton consistent with the robust cost (same minimisers).
#pragma once

#include <ceres/ceres.h>

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

  int num_residuals() const { return 2 * static_cast<int>(observations->size()); }
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
  // Observation i: its 2 residuals and their derivative w.r.t. its keypoint.
  ARCO_FLATTEN int ResidualWithDerivative(int i,
                             const Eigen::Vector3d* points,
                             double* residual,
                             Eigen::Matrix3d* d_residual,
                             int* keypoint) const {
    using Jet3 = ceres::Jet<double, 3>;
    const PixelObservation& o = (*observations)[i];
    *keypoint = o.keypoint;
    Jet3 q[3], pixel[2], r[2];
    for (int c = 0; c < 3; ++c) q[c] = Jet3(points[o.keypoint][c], c);
    if (!o.camera->ProjectToPixel(q, pixel)) {
      r[0] = Jet3(o.sqrt_weight * 10.0 * std::sqrt(loss_c2));
      r[1] = Jet3(0.0);
    } else {
      r[0] = pixel[0] - o.pixel.x();
      r[1] = pixel[1] - o.pixel.y();
      const Jet3 scale = o.sqrt_weight * CauchyScale(r[0] * r[0] + r[1] * r[1], loss_c2);
      r[0] *= scale;
      r[1] *= scale;
    }
    for (int j = 0; j < 2; ++j) residual[j] = r[j].a, d_residual->row(j) = r[j].v.transpose();
    return 2;
  }
};

struct PointResiduals {
  const HandModel* model;
  const HandPointsMm* targets;  // NaN = missing (zero residual)
  double loss_c2;               // squared Cauchy scale, mm^2

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

// Jacobians by the chain rule: keypoint Jacobians from the kinematic tree
// (HandPointsAndJacobians), times the 2x3 (projection + robust scaling) or 3x3
// (robust scaling) derivative of each residual with respect to its keypoint,
// both from small Jets. Values come from the templated residual functors.
template <typename Residuals>
class HandCostFunction : public ceres::CostFunction {
 public:
  explicit HandCostFunction(Residuals residuals) : r_(residuals) {
    set_num_residuals(r_.num_residuals());
    mutable_parameter_block_sizes()->assign({3, 3, kNumJointDofs});
  }
  ARCO_FLATTEN bool Evaluate(double const* const* x,
                             double* residuals,
                             double** jacobians) const override {
    if (jacobians == nullptr) {
      r_(x[0], x[1], x[2], residuals);
      return true;
    }
    Eigen::Vector3d points[kNumHandKeypoints];
    HandPointJacobian point_jacobians[kNumHandKeypoints];
    HandPointsAndJacobians(*r_.model, x[0], x[1], x[2], points, point_jacobians);
    const int sizes[3] = {3, 3, kNumJointDofs};
    const int offsets[3] = {0, 3, 6};
    Eigen::Matrix<double, 3, 3> d_residual;  // rows: residual components (<= 3)
    int row = 0;
    for (int i = 0; row < num_residuals(); ++i) {
      int keypoint;
      const int dim = r_.ResidualWithDerivative(i, points, residuals + row, &d_residual, &keypoint);
      for (int j = 0; j < dim; ++j, ++row) {
        const Eigen::Matrix<double, 1, 6 + kNumJointDofs> d =
            d_residual.row(j) * point_jacobians[keypoint];
        for (int b = 0; b < 3; ++b) {
          if (jacobians[b] == nullptr) continue;
          for (int c = 0; c < sizes[b]; ++c) jacobians[b][row * sizes[b] + c] = d[offsets[b] + c];
        }
      }
    }
    return true;
  }

 private:
  Residuals r_;
};

}  // namespace arco::hand::internal
