#include "arco/hand/fusion.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "arco/geometry/rotation.h"
#include "arco/util/stats.h"

namespace arco::hand {
namespace {

const double kNaN = std::nan("");

}  // namespace

Status HandFusionOptions::Validate() const {
  auto bad = [](const std::string& m) { return Status::Error("HandFusionOptions: " + m); };
  if (!(min_confidence >= 0 && min_confidence <= 1)) return bad("min_confidence must be in [0, 1]");
  if (!(view_angle_power >= 0 && std::isfinite(view_angle_power))) {
    return bad("view_angle_power must be finite and >= 0");
  }
  if (!(view_angle_floor > 0 && view_angle_floor <= 1))
    return bad("view_angle_floor must be in (0, 1]");
  return Status::Ok();
}

double AngleAboutAxis(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& axis) {
  const double sign = rotation.w() < 0 ? -1.0 : 1.0;
  return 2.0 * std::atan2(sign * rotation.vec().dot(axis), sign * rotation.w());
}

void DecomposeUniversalJoint(const Eigen::Matrix3d& rotation,
                             const Eigen::Vector3d& flex_axis,
                             const Eigen::Vector3d& abd_axis,
                             double* flex,
                             double* abd) {
  // R a_flex = R(a_abd, abd) a_flex: abd is the angle from a_flex to R a_flex
  // about a_abd (a_flex is perpendicular to a_abd).
  const Eigen::Vector3d moved = rotation * flex_axis;
  *abd = std::atan2(abd_axis.dot(flex_axis.cross(moved)), flex_axis.dot(moved));
  const Eigen::Matrix3d rest = Eigen::AngleAxisd(-*abd, abd_axis).toRotationMatrix() * rotation;
  *flex = AngleAboutAxis(Eigen::Quaterniond(rest), flex_axis);
}

FusedHand FuseViewHands(const HandModel& model,
                        const std::vector<Camera>& cameras,
                        const std::vector<ViewHand3d>& views,
                        const HandFusionOptions& options) {
  if (cameras.size() != views.size()) {
    throw std::invalid_argument("FuseViewHands: " + std::to_string(cameras.size()) +
                                " cameras but " + std::to_string(views.size()) + " views");
  }
  const Status valid = options.Validate();
  if (!valid.ok()) throw std::invalid_argument(valid.message());
  const size_t n = views.size();
  FusedHand out;
  out.view_weights.assign(n, 0.0);
  out.view_fit_rms_mm.assign(n, kNaN);
  std::vector<HandPose> poses(n);
  for (size_t v = 0; v < n; ++v) {
    const ViewHand3d& view = views[v];
    if (!(view.confidence >= options.min_confidence)) continue;
    const HandPointsMm& p = view.points_in_camera_mm;
    int finite = 0;
    for (const auto& q : p) finite += q.allFinite();
    if (finite < 6 || !p[0].allFinite() || !p[5].allFinite() || !p[17].allFinite()) continue;
    const Eigen::Vector3d normal = (p[5] - p[0]).cross(p[17] - p[0]);
    if (!(normal.norm() > 1e-9)) continue;  // degenerate palm
    const Eigen::Vector3d to_camera =
        p[0].z() > 0 ? Eigen::Vector3d(-p[0].normalized()) : Eigen::Vector3d(0, 0, -1);
    const double cosine = std::abs(normal.normalized().dot(to_camera));
    // Into world orientation, wrist at the origin, model size.
    const Eigen::Matrix3d world_from_cam = cameras[v].cam_from_world.rotation.transpose();
    HandPointsMm q;
    for (int k = 0; k < kNumHandKeypoints; ++k) q[k] = world_from_cam * (p[k] - p[0]);
    if (options.normalise_scale) {
      std::vector<double> ratios;
      for (int k = 1; k < kNumHandKeypoints; ++k) {
        const double len = (q[k] - q[ParentKeypoint(k)]).norm();
        if (std::isfinite(len) && len > 1e-9) ratios.push_back(model.bone_length_mm(k) / len);
      }
      if (ratios.size() < 3) continue;
      const double s = UpperMedian(ratios);
      for (auto& x : q) x *= s;
    }
    const HandFit3dResult fit = FitHandToPoints3d(model, q, HandFit3dOptions{});
    if (!fit.ok) continue;
    poses[v] = fit.pose;
    out.view_fit_rms_mm[v] = fit.rms_error_mm;
    out.view_weights[v] = view.confidence * std::pow(std::max(cosine, options.view_angle_floor),
                                                     options.view_angle_power);
    ++out.num_views_used;
  }
  double total = 0;
  for (double w : out.view_weights) total += w;
  if (out.num_views_used == 0 || !(total > 0)) {
    out.problem = "no view has a usable 3D hand";
    out.pose = ClampToLimits(model, HandPose{});
    return out;
  }
  for (double& w : out.view_weights) w /= total;

  // Markley averages of the wrist rotation and of every joint's local rotation.
  std::vector<Eigen::Quaterniond> q;
  std::vector<double> w;
  auto average = [&](auto rotation_of_view) {
    q.clear();
    w.clear();
    for (size_t v = 0; v < n; ++v) {
      if (out.view_weights[v] <= 0) continue;
      q.emplace_back(rotation_of_view(v));
      w.push_back(out.view_weights[v]);
    }
    return *AverageQuaternions(q, w);
  };
  std::vector<std::array<Eigen::Matrix3d, kNumHandKeypoints>> local(n);
  for (size_t v = 0; v < n; ++v) {
    if (out.view_weights[v] > 0) local[v] = LocalJointRotations(model, poses[v]);
  }
  HandPose fused;
  fused.world_from_wrist.rotation =
      average([&](size_t v) { return poses[v].world_from_wrist.rotation; }).toRotationMatrix();
  for (int f = 0; f < kNumFingers; ++f) {
    const Finger finger = static_cast<Finger>(f);
    const int k0 = KeypointIndex(finger, 0);
    const Eigen::Quaterniond base = average([&](size_t v) { return local[v][k0]; });
    DecomposeUniversalJoint(base.toRotationMatrix(),
                            model.axis(DofIndex(finger, FingerDof::kBaseFlex)),
                            model.axis(DofIndex(finger, FingerDof::kBaseAbd)),
                            &fused.angle_rad(finger, FingerDof::kBaseFlex),
                            &fused.angle_rad(finger, FingerDof::kBaseAbd));
    for (int j = 1; j <= 2; ++j) {
      const FingerDof dof = j == 1 ? FingerDof::kMiddleFlex : FingerDof::kDistalFlex;
      fused.angle_rad(finger, dof) = AngleAboutAxis(
          average([&](size_t v) { return local[v][k0 + j]; }), model.axis(DofIndex(finger, dof)));
    }
  }
  out.pose = ClampToLimits(model, fused);
  out.ok = true;
  return out;
}

}  // namespace arco::hand
