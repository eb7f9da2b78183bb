// Options validation and the per-frame pose of a fitted instrument template.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "arco/instrument/rigid_align.h"
#include "arco/instrument/template_fit.h"

namespace arco {
namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace

Status InstrumentFitOptions::Validate() const {
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (scale == Scale::kGiven && !positive(world_units_per_mm)) {
    return Status::Error("instrument fit: world_units_per_mm must be > 0 with Scale::kGiven");
  }
  if (max_iterations < 1) return Status::Error("instrument fit: max_iterations must be >= 1");
  if (!positive(convergence_mm) || !positive(point_gate_factor) || !positive(min_point_gate_mm) ||
      !positive(max_point_gate_mm) || !positive(frame_gate_sigmas) || !positive(min_spread_mm)) {
    return Status::Error("instrument fit: tolerances and gates must be > 0");
  }
  if (min_point_gate_mm > max_point_gate_mm) {
    return Status::Error("instrument fit: min_point_gate_mm exceeds max_point_gate_mm");
  }
  if (min_observations_per_point < 1) {
    return Status::Error("instrument fit: min_observations_per_point must be >= 1");
  }
  if (!(min_front_agreement >= 0.5 && min_front_agreement <= 1.0)) {
    return Status::Error("instrument fit: min_front_agreement must be in [0.5, 1]");
  }
  if (num_threads < 0) return Status::Error("instrument fit: num_threads must be >= 0");
  return strings.Validate();
}

const char* FrameFitStatusName(FrameFitStatus status) {
  switch (status) {
    case FrameFitStatus::kOk:
      return "ok";
    case FrameFitStatus::kHighResidual:
      return "high_residual";
    case FrameFitStatus::kTooFewPoints:
      return "too_few_points";
  }
  return "unknown";
}

InstrumentFramePose FitFramePose(const InstrumentTemplate& instrument,
                                 const Eigen::Matrix3Xd& keypoints_in_world,
                                 double point_gate_mm,
                                 double min_spread_mm) {
  const int num_keypoints = static_cast<int>(instrument.keypoints_in_instrument.size());
  if (keypoints_in_world.cols() != num_keypoints) {
    throw std::invalid_argument("FitFramePose: expected " + std::to_string(num_keypoints) +
                                " keypoint columns, got " +
                                std::to_string(keypoints_in_world.cols()));
  }
  Eigen::Matrix3Xd source(3, num_keypoints);
  for (int k = 0; k < num_keypoints; ++k) source.col(k) = instrument.keypoints_in_instrument[k];
  const double u = instrument.world_units_per_mm;
  const RigidAlignment a =
      AlignRigidRobust(source, keypoints_in_world / u, point_gate_mm, min_spread_mm);
  InstrumentFramePose out;
  out.num_observed = a.num_common;
  out.rms_residual_mm = kNaN;
  if (!a.ok) return out;
  out.status = FrameFitStatus::kOk;
  out.world_from_instrument =
      SimMatrix3d(u, a.target_from_source.rotation, u * a.target_from_source.translation);
  out.rms_residual_mm = a.rms_residual;
  out.num_inliers = a.num_inliers;
  out.inlier_mask = a.inlier_mask;
  return out;
}

double PoseResidualMm(const InstrumentTemplate& instrument,
                      const SimMatrix3d& world_from_instrument,
                      const Eigen::Matrix3Xd& keypoints_in_world,
                      uint32_t inlier_mask) {
  double sum_sq = 0;
  int n = 0;
  const int cols = std::min<int>(keypoints_in_world.cols(),
                                 static_cast<int>(instrument.keypoints_in_instrument.size()));
  for (int k = 0; k < cols; ++k) {
    if (!(inlier_mask & (1u << k))) continue;
    const Eigen::Vector3d& p = instrument.keypoints_in_instrument[k];
    const Eigen::Vector3d x = keypoints_in_world.col(k);
    if (!p.allFinite() || !x.allFinite()) continue;
    sum_sq += ((world_from_instrument * p - x) / world_from_instrument.scale).squaredNorm();
    ++n;
  }
  return n > 0 ? std::sqrt(sum_sq / n) : kNaN;
}

}  // namespace arco
