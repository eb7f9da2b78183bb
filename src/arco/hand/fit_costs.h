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

// Reprojection cost with the chain rule split in two: FK in Jet<26> once, then
// each projection (and its robust scaling) in Jet<3> with respect to the 3D
// point, multiplied out (2x3 * 3x26). Several times cheaper than projecting
// 26-wide Jets; same values and derivatives.
class ReprojectionCost : public ceres::CostFunction {
 public:
  explicit ReprojectionCost(ReprojectionResiduals residuals) : r_(residuals) {
    set_num_residuals(r_.num_residuals());
    mutable_parameter_block_sizes()->assign({3, 3, kNumJointDofs});
  }
  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const override {
    if (jacobians == nullptr) {
      r_(x[0], x[1], x[2], residuals);
      return true;
    }
    using Jet = ceres::Jet<double, 6 + kNumJointDofs>;
    using Jet3 = ceres::Jet<double, 3>;
    Jet p[6 + kNumJointDofs];
    for (int i = 0; i < 3; ++i) p[i] = Jet(x[0][i], i), p[3 + i] = Jet(x[1][i], 3 + i);
    for (int i = 0; i < kNumJointDofs; ++i) p[6 + i] = Jet(x[2][i], 6 + i);
    Eigen::Matrix<Jet, 3, 1> points[kNumHandKeypoints];
    HandPointsInWorld(*r_.model, p, p + 3, p + 6, points);
    const int sizes[3] = {3, 3, kNumJointDofs};
    const int offsets[3] = {0, 3, 6};
    for (size_t i = 0; i < r_.observations->size(); ++i) {
      const PixelObservation& o = (*r_.observations)[i];
      const Eigen::Matrix<Jet, 3, 1>& point = points[o.keypoint];
      Jet3 q[3], pixel[2], r[2];
      for (int c = 0; c < 3; ++c) q[c] = Jet3(point[c].a, c);
      if (!o.camera->ProjectToPixel(q, pixel)) {
        r[0] = Jet3(o.sqrt_weight * 10.0 * std::sqrt(r_.loss_c2));
        r[1] = Jet3(0.0);
      } else {
        r[0] = pixel[0] - o.pixel.x();
        r[1] = pixel[1] - o.pixel.y();
        const Jet3 scale = o.sqrt_weight * CauchyScale(r[0] * r[0] + r[1] * r[1], r_.loss_c2);
        r[0] *= scale;
        r[1] *= scale;
      }
      for (int row = 0; row < 2; ++row) {
        const int out_row = 2 * static_cast<int>(i) + row;
        residuals[out_row] = r[row].a;
        const Eigen::Matrix<double, 1, 6 + kNumJointDofs> d = r[row].v[0] * point[0].v.transpose() +
                                                              r[row].v[1] * point[1].v.transpose() +
                                                              r[row].v[2] * point[2].v.transpose();
        for (int b = 0; b < 3; ++b) {
          if (jacobians[b] == nullptr) continue;
          for (int j = 0; j < sizes[b]; ++j)
            jacobians[b][out_row * sizes[b] + j] = d[offsets[b] + j];
        }
      }
    }
    return true;
  }

 private:
  ReprojectionResiduals r_;
};

// A cost over {3, 3, 20} whose Jacobian comes from one forward pass in
// ceres::Jet<double, 26> (cheaper than per-residual autodiff blocks).
template <typename Residuals>
class HandCostFunction : public ceres::CostFunction {
 public:
  explicit HandCostFunction(Residuals residuals) : residuals_(residuals) {
    set_num_residuals(residuals_.num_residuals());
    mutable_parameter_block_sizes()->assign({3, 3, kNumJointDofs});
  }
  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const override {
    if (jacobians == nullptr) {
      residuals_(x[0], x[1], x[2], residuals);
      return true;
    }
    using Jet = ceres::Jet<double, 6 + kNumJointDofs>;
    Jet p[6 + kNumJointDofs];
    for (int i = 0; i < 3; ++i) p[i] = Jet(x[0][i], i), p[3 + i] = Jet(x[1][i], 3 + i);
    for (int i = 0; i < kNumJointDofs; ++i) p[6 + i] = Jet(x[2][i], 6 + i);
    const int n = num_residuals();
    std::vector<Jet> r(n);
    residuals_(p, p + 3, p + 6, r.data());
    const int sizes[3] = {3, 3, kNumJointDofs};
    const int offsets[3] = {0, 3, 6};
    for (int row = 0; row < n; ++row) {
      residuals[row] = r[row].a;
      for (int b = 0; b < 3; ++b) {
        if (jacobians[b] == nullptr) continue;
        for (int i = 0; i < sizes[b]; ++i)
          jacobians[b][row * sizes[b] + i] = r[row].v[offsets[b] + i];
      }
    }
    return true;
  }

 private:
  Residuals residuals_;
};

}  // namespace arco::hand::internal
