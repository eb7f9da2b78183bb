#include "arco/hand/graft.h"

#include <cmath>
#include <stdexcept>

#include "arco/geometry/alignment.h"

namespace arco::hand {

Status WristGraftOptions::Validate() const {
  if (!(robust_loss_mm >= 0) || !std::isfinite(robust_loss_mm)) {
    return Status::Error("WristGraftOptions: robust_loss_mm must be finite and >= 0");
  }
  return Status::Ok();
}

WristGraftResult GraftHandAtWrist(const HandModel& model,
                                  const HandPose& hand,
                                  const HandPointsMm& body_hand_in_world_mm,
                                  const std::vector<double>& weights,
                                  const WristGraftOptions& options) {
  if (!weights.empty() && weights.size() != kNumHandKeypoints) {
    throw std::invalid_argument("GraftHandAtWrist: weights must be empty or have 21 entries");
  }
  const Status valid = options.Validate();
  if (!valid.ok()) throw std::invalid_argument(valid.message());
  WristGraftResult out;
  out.pose = hand;
  const HandPointsMm model_points = ForwardKinematics(model, hand);
  const Eigen::Vector3d& body_wrist = body_hand_in_world_mm[0];
  if (options.pin_wrist && !body_wrist.allFinite()) {
    out.problem = "pin_wrist: the body wrist keypoint is missing";
    return out;
  }
  // With a pinned wrist both sets are centred on their wrists and the wrist
  // gets an overwhelming weight, so the alignment keeps it fixed.
  std::vector<Eigen::Vector3d> source, target;
  std::vector<double> w;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const double wk = weights.empty() ? 1.0 : weights[k];
    if (!body_hand_in_world_mm[k].allFinite() || !model_points[k].allFinite() || !(wk > 0) ||
        !std::isfinite(wk)) {
      continue;
    }
    source.push_back(model_points[k] -
                     (options.pin_wrist ? model_points[0] : Eigen::Vector3d::Zero()));
    target.push_back(body_hand_in_world_mm[k] -
                     (options.pin_wrist ? body_wrist : Eigen::Vector3d::Zero()));
    w.push_back(wk);
  }
  out.num_points = static_cast<int>(source.size());
  AlignmentOptions align;
  if (options.robust_loss_mm > 0) {
    align.loss = RobustLoss::kCauchy;
    align.loss_scale = options.robust_loss_mm;
  }
  std::optional<AlignmentResult> fit;
  if (options.pin_wrist) {
    // Rotation about the wrist only: add the origin pair with a dominant weight.
    double total = 0;
    for (double x : w) total += x;
    source.push_back(Eigen::Vector3d::Zero());
    target.push_back(Eigen::Vector3d::Zero());
    w.push_back(1e6 * (total + 1));
  }
  if (out.num_points >= 3 || (options.pin_wrist && out.num_points >= 2)) {
    fit = AlignPoints(source, target, w, align);
  }
  if (!fit) {
    out.problem = "fewer than 3 usable, non-collinear hand keypoints from the body detector";
    return out;
  }
  out.moved_from_input.rotation = fit->target_from_source.RotationMatrix();
  out.moved_from_input.translation = fit->target_from_source.translation;
  if (options.pin_wrist) {
    // p -> R (p - m_wrist) + b_wrist (drop the tiny residual translation).
    out.moved_from_input.translation = body_wrist - out.moved_from_input.rotation * model_points[0];
  }
  out.pose.world_from_wrist = out.moved_from_input * hand.world_from_wrist;
  const HandPointsMm moved = ForwardKinematics(model, out.pose);
  double sum = 0, sum_w = 0;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const double wk = weights.empty() ? 1.0 : weights[k];
    if (!body_hand_in_world_mm[k].allFinite() || !(wk > 0) || !std::isfinite(wk)) continue;
    sum += wk * (moved[k] - body_hand_in_world_mm[k]).squaredNorm();
    sum_w += wk;
  }
  out.rms_mm = std::sqrt(sum / sum_w);
  out.ok = true;
  return out;
}

}  // namespace arco::hand
