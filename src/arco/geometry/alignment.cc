#include "arco/geometry/alignment.h"

#include <Eigen/SVD>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "arco/geometry/rotation.h"

namespace arco {
namespace {

// Closed-form weighted Umeyama (1991) solution; nullopt when degenerate.
std::optional<Sim3d> SolveWeighted(const std::vector<Eigen::Vector3d>& source,
                                   const std::vector<Eigen::Vector3d>& target,
                                   const std::vector<double>& weights,
                                   bool estimate_scale) {
  double total = 0;
  int used = 0;
  Eigen::Vector3d mean_source = Eigen::Vector3d::Zero(), mean_target = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < source.size(); ++i) {
    if (weights[i] <= 0) continue;
    total += weights[i];
    ++used;
    mean_source += weights[i] * source[i];
    mean_target += weights[i] * target[i];
  }
  if (used < 3 || !(total > 0)) return std::nullopt;
  mean_source /= total;
  mean_target /= total;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // target x source
  double variance_source = 0;
  for (size_t i = 0; i < source.size(); ++i) {
    if (weights[i] <= 0) continue;
    const Eigen::Vector3d s = source[i] - mean_source;
    covariance += weights[i] * (target[i] - mean_target) * s.transpose();
    variance_source += weights[i] * s.squaredNorm();
  }
  covariance /= total;
  variance_source /= total;
  const double magnitude = 1.0 + mean_source.squaredNorm();
  if (!(variance_source > 1e-24 * magnitude)) return std::nullopt;  // coincident points
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d d = svd.singularValues();
  // Rank < 2: all points on a line (or the target collapsed), rotation undetermined.
  if (!(d(1) > 1e-12 * d(0))) return std::nullopt;
  bool reflected = false;  // no mirror: the last singular direction flipped
  const Eigen::Matrix3d rotation = ProperRotationFromSvd(svd.matrixU(), svd.matrixV(), &reflected);
  const Eigen::Vector3d signs(1, 1, reflected ? -1 : 1);
  const double scale = estimate_scale ? d.dot(signs) / variance_source : 1.0;
  if (!(scale > 0) || !std::isfinite(scale)) return std::nullopt;
  const Eigen::Vector3d translation = mean_target - scale * rotation * mean_source;
  return Sim3d(scale, Eigen::Quaterniond(rotation), translation);
}

double RobustWeight(RobustLoss loss, double scale, double residual) {
  switch (loss) {
    case RobustLoss::kHuber:
      return residual <= scale ? 1.0 : scale / residual;
    case RobustLoss::kCauchy: {
      const double u = residual / scale;
      return 1.0 / (1.0 + u * u);
    }
    case RobustLoss::kNone:
      break;
  }
  return 1.0;
}

}  // namespace

void AlignmentOptions::Validate() const {
  if (!(loss_scale > 0) || !std::isfinite(loss_scale)) {
    throw std::invalid_argument("AlignmentOptions: loss_scale must be positive and finite");
  }
  if (max_iterations < 1)
    throw std::invalid_argument("AlignmentOptions: max_iterations must be >= 1");
  if (!(tolerance >= 0)) throw std::invalid_argument("AlignmentOptions: tolerance must be >= 0");
}

std::optional<AlignmentResult> AlignPoints(const std::vector<Eigen::Vector3d>& source,
                                           const std::vector<Eigen::Vector3d>& target,
                                           const std::vector<double>& weights,
                                           const AlignmentOptions& options) {
  options.Validate();
  if (source.size() != target.size() || (!weights.empty() && weights.size() != source.size())) {
    throw std::invalid_argument("AlignPoints: source, target and weights differ in size");
  }
  const size_t n = source.size();
  std::vector<double> base(n, 0.0);
  for (size_t i = 0; i < n; ++i) {
    const double w = weights.empty() ? 1.0 : weights[i];
    if (!(w >= 0) || !std::isfinite(w)) {
      throw std::invalid_argument("AlignPoints: weights must be finite and >= 0");
    }
    if (source[i].allFinite() && target[i].allFinite()) base[i] = w;
  }
  std::optional<Sim3d> transform = SolveWeighted(source, target, base, options.estimate_scale);
  if (!transform) return std::nullopt;

  AlignmentResult result;
  result.robust_weights.assign(n, 1.0);
  auto update_residuals = [&] {
    result.residuals.assign(n, std::numeric_limits<double>::quiet_NaN());
    for (size_t i = 0; i < n; ++i) {
      if (base[i] > 0) result.residuals[i] = (*transform * source[i] - target[i]).norm();
    }
  };
  update_residuals();
  if (options.loss != RobustLoss::kNone) {
    result.converged = false;
    std::vector<double> combined(n);
    for (int iteration = 1; iteration <= options.max_iterations; ++iteration) {
      for (size_t i = 0; i < n; ++i) {
        combined[i] =
            base[i] > 0
                ? base[i] * RobustWeight(options.loss, options.loss_scale, result.residuals[i])
                : 0.0;
      }
      const std::optional<Sim3d> next =
          SolveWeighted(source, target, combined, options.estimate_scale);
      if (!next) break;  // reweighting left too little support: keep the last solution
      double change = 0;
      for (size_t i = 0; i < n; ++i) {
        if (base[i] > 0)
          change = std::max(change, (*next * source[i] - *transform * source[i]).norm());
      }
      transform = next;
      result.iterations = iteration;
      update_residuals();
      if (change <= options.tolerance) {
        result.converged = true;
        break;
      }
    }
  }
  double sum = 0, total = 0;
  for (size_t i = 0; i < n; ++i) {
    result.robust_weights[i] =
        base[i] > 0 ? RobustWeight(options.loss, options.loss_scale, result.residuals[i]) : 0.0;
    if (base[i] > 0) {
      sum += base[i] * result.residuals[i] * result.residuals[i];
      total += base[i];
    }
  }
  result.rms_error = std::sqrt(sum / total);
  result.target_from_source = *transform;
  return result;
}

}  // namespace arco
