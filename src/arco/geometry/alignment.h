// Weighted, optionally robust alignment of corresponding 3D point sets:
// find T (rigid, or similarity when estimate_scale) minimising
//   sum_i w_i rho(|T(source_i) - target_i|).
// Each step is the closed-form weighted Umeyama solution (Umeyama, PAMI 1991;
// Kabsch 1976 without scale); a robust loss is handled by iteratively reweighted
// least squares (IRLS) started from the plain weighted solution.
// Uses: instrument template fitting, grafting the hand onto the wrist.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "arco/geometry/transform.h"

namespace arco {

enum class RobustLoss {
  kNone,    // rho(r) = r^2 / 2: one weighted least-squares solve
  kHuber,   // quadratic up to loss_scale, linear beyond
  kCauchy,  // rho(r) = c^2/2 log(1 + (r/c)^2): gross outliers get ~0 weight
};

struct AlignmentOptions {
  bool estimate_scale = false;  // similarity (Umeyama) instead of rigid (Kabsch)
  RobustLoss loss = RobustLoss::kNone;
  double loss_scale = 1.0;  // residual where the robust loss bends, in point units (e.g. mm)
  int max_iterations = 50;  // IRLS iterations (robust losses only)
  // IRLS stops when the largest change of a transformed source point is below this
  // (point units).
  double tolerance = 1e-9;
  // Throws std::invalid_argument with a readable message on a bad value.
  void Validate() const;
};

struct AlignmentResult {
  Sim3d target_from_source;       // scale == 1 unless estimate_scale
  double rms_error = 0;           // sqrt(sum w_i r_i^2 / sum w_i) over usable points, input weights
  std::vector<double> residuals;  // |T(source_i) - target_i|; NaN for unusable points
  std::vector<double>
      robust_weights;     // IRLS weight per point (1 without a robust loss; 0 unusable)
  int iterations = 0;     // IRLS iterations done (0 without a robust loss)
  bool converged = true;  // false when IRLS hit max_iterations
};

// `weights` empty means all 1. Points with a non-finite coordinate or zero weight
// are unusable (ignored). Nullopt when the usable points cannot fix the transform:
// fewer than 3, total weight 0, all coincident, or all on one line.
// Throws std::invalid_argument on mismatched sizes, negative or non-finite
// weights, or invalid options.
std::optional<AlignmentResult> AlignPoints(const std::vector<Eigen::Vector3d>& source,
                                           const std::vector<Eigen::Vector3d>& target,
                                           const std::vector<double>& weights,
                                           const AlignmentOptions& options);

}  // namespace arco
