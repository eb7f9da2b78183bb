#include "arco/calibration/bundle_adjustment.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>

#include "arco/calibration/bundle_solver.h"
#include "arco/calibration/pose_parameters.h"
#include "arco/calibration/reprojection_cost.h"

namespace arco::calibration {
namespace {

// Per camera in the parameter buffer: cam_from_world (pose_parameters.h), then the
// intrinsics (camera.h IntrinsicIndex order).
constexpr int kCameraStride = kPoseParams + kNumIntrinsics;

// Reprojection of a free point: x_cam = cam_from_world * X.
struct PointReprojection {
  explicit PointReprojection(const Eigen::Vector2d& px) : observed_px(px) {}
  template <typename T>
  bool operator()(const T* cam, const T* intrinsics, const T* point, T* residual) const {
    return ReprojectionResidual(cam, intrinsics, point, observed_px, residual);
  }
  Eigen::Vector2d observed_px;
};

// Reprojection of a point of the rigid body: X = world_from_body * X_template.
struct RigidReprojection {
  explicit RigidReprojection(const Eigen::Vector2d& px) : observed_px(px) {}
  template <typename T>
  bool operator()(const T* cam,
                  const T* intrinsics,
                  const T* world_from_body,
                  const T* point_in_body,
                  T* residual) const {
    T world_point[3];
    TransformByPose(world_from_body, point_in_body, world_point);
    return ReprojectionResidual(cam, intrinsics, world_point, observed_px, residual);
  }
  Eigen::Vector2d observed_px;
};

// MidpointDistance's residual.
struct MidpointDistanceCost {
  MidpointDistanceCost(double target, double weight) : target(target), weight(weight) {}
  template <typename T>
  bool operator()(const T* a0, const T* a1, const T* b0, const T* b1, T* residual) const {
    T sq = T(0);
    for (int i = 0; i < 3; ++i) {
      const T d = T(0.5) * (a0[i] + a1[i]) - T(0.5) * (b0[i] + b1[i]);
      sq += d * d;
    }
    residual[0] = T(weight) * (ceres::sqrt(sq) - T(target));
    return true;
  }
  double target, weight;
};

}  // namespace

Status RigAdjustmentOptions::Validate(int num_cameras, int num_template_points) const {
  const auto camera_ok = [num_cameras](int c) { return c >= 0 && c < num_cameras; };
  if (!camera_ok(reference_camera)) {
    return Status::Error("bundle adjustment: reference_camera " + std::to_string(reference_camera) +
                         " is not a camera of the rig's " + std::to_string(num_cameras));
  }
  for (int c : cameras) {
    if (!camera_ok(c)) {
      return Status::Error("bundle adjustment: camera " + std::to_string(c) +
                           " is not a camera of the rig's " + std::to_string(num_cameras));
    }
  }
  if (!(loss_scale_px > 0) || !std::isfinite(loss_scale_px)) {
    return Status::Error("bundle adjustment: loss_scale_px must be a finite value > 0");
  }
  if (max_iterations < 1) return Status::Error("bundle adjustment: max_iterations must be >= 1");
  for (int k : {scale.a0, scale.a1, scale.b0, scale.b1}) {
    if (k < 0 || k >= num_template_points) {
      return Status::Error("bundle adjustment: the scale's template point " + std::to_string(k) +
                           " is not one of the body's " + std::to_string(num_template_points));
    }
  }
  if (!(scale.length > 0) || !std::isfinite(scale.length) || !(scale.weight > 0) ||
      !std::isfinite(scale.weight)) {
    return Status::Error("bundle adjustment: the scale's length and weight must be finite and > 0");
  }
  return Status::Ok();
}

StatusOr<BundleAdjustmentSummary> AdjustRig(const RigAdjustmentOptions& options,
                                            const std::vector<BundleTrack>& tracks,
                                            Rig* rig,
                                            RigidBody* body) {
  const int num_cameras = static_cast<int>(rig->cameras.size());
  const int num_k = static_cast<int>(body->points.size());
  const int num_frames = static_cast<int>(body->rotation.size());
  ARCO_RETURN_IF_ERROR(options.Validate(num_cameras, num_k));
  if (body->translation.size() != body->rotation.size() ||
      body->valid.size() != body->rotation.size()) {
    return Status::Error(
        "bundle adjustment: the body's rotations, translations and valid flags "
        "differ in count");
  }
  for (const BundleTrack& track : tracks) {
    if (track.rigid >= num_k ||
        (track.rigid >= 0 &&
         (track.frame < 0 || track.frame >= num_frames || !body->valid[track.frame]))) {
      return Status::Error(
          "bundle adjustment: a rigid track's template point or frame is not "
          "one of the body's");
    }
    for (const BundleObservation& o : track.observations) {
      if (o.camera < 0 || o.camera >= num_cameras) {
        return Status::Error("bundle adjustment: an observation names camera " +
                             std::to_string(o.camera) + " of the rig's " +
                             std::to_string(num_cameras));
      }
    }
  }
  // The parameters in one buffer, in a fixed order (cameras, template, body poses, free
  // points): Ceres orders the blocks of an elimination group by address, so separate
  // allocations would make the solution depend on where the heap put them (the last bits
  // differ from run to run).
  int64_t num_free = 0;
  std::vector<int64_t> free_index(tracks.size(), -1);
  for (size_t i = 0; i < tracks.size(); ++i)
    if (tracks[i].rigid < 0) free_index[i] = num_free++;
  const int64_t template_offset = int64_t{num_cameras} * kCameraStride;
  const int64_t pose_offset = template_offset + 3 * num_k;
  const int64_t point_offset = pose_offset + int64_t{kPoseParams} * num_frames;
  std::vector<double> x(point_offset + 3 * num_free, 0.0);
  for (int c = 0; c < num_cameras; ++c) {
    const Camera& cam = rig->cameras[c];
    PoseToParams(
        cam.cam_from_world.rotation, cam.cam_from_world.translation, &x[c * kCameraStride]);
    const auto intrinsics = cam.Intrinsics();
    std::copy(intrinsics.begin(), intrinsics.end(), &x[c * kCameraStride + kPoseParams]);
  }
  for (int k = 0; k < num_k; ++k)
    for (int i = 0; i < 3; ++i)
      x[template_offset + 3 * k + i] = body->points[k].allFinite() ? body->points[k][i] : 0.0;
  for (int f = 0; f < num_frames; ++f)
    PoseToParams(body->rotation[f], body->translation[f], &x[pose_offset + kPoseParams * f]);
  for (size_t i = 0; i < tracks.size(); ++i)
    if (free_index[i] >= 0)
      for (int d = 0; d < 3; ++d)
        x[point_offset + 3 * free_index[i] + d] = tracks[i].point_in_world[d];

  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  std::unique_ptr<ceres::LossFunction> loss;
  if (options.loss == BundleLoss::kCauchy)
    loss = std::make_unique<ceres::CauchyLoss>(options.loss_scale_px);
  else
    loss = std::make_unique<ceres::HuberLoss>(options.loss_scale_px);
  for (size_t i = 0; i < tracks.size(); ++i) {
    const BundleTrack& t = tracks[i];
    for (const BundleObservation& o : t.observations) {
      double* cam = &x[o.camera * kCameraStride];
      double* intrinsics = cam + kPoseParams;
      if (t.rigid < 0) {
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<PointReprojection, 2, 6, kNumIntrinsics, 3>(
                new PointReprojection(o.pixel)),
            loss.get(),
            cam,
            intrinsics,
            &x[point_offset + 3 * free_index[i]]);
      } else {
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<RigidReprojection, 2, 6, kNumIntrinsics, 6, 3>(
                new RigidReprojection(o.pixel)),
            loss.get(),
            cam,
            intrinsics,
            &x[pose_offset + kPoseParams * t.frame],
            &x[template_offset + 3 * t.rigid]);
      }
    }
  }
  const MidpointDistance& scale = options.scale;
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<MidpointDistanceCost, 1, 3, 3, 3, 3>(
                               new MidpointDistanceCost(scale.length, scale.weight)),
                           nullptr,
                           &x[template_offset + 3 * scale.a0],
                           &x[template_offset + 3 * scale.a1],
                           &x[template_offset + 3 * scale.b0],
                           &x[template_offset + 3 * scale.b1]);
  std::vector<int> held;  // every intrinsic but fx and fy
  for (int i = 0; i < kNumIntrinsics; ++i)
    if (i != kFx && i != kFy) held.push_back(i);
  // Schur elimination: body poses and free points first (group 0), then cameras and template.
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (int c = 0; c < num_cameras; ++c) {
    double* cam = &x[c * kCameraStride];
    if (!problem.HasParameterBlock(cam)) continue;
    if (c == options.reference_camera) problem.SetParameterBlockConstant(cam);
    if (options.refine_focal)
      problem.SetManifold(cam + kPoseParams, new ceres::SubsetManifold(kNumIntrinsics, held));
    else
      problem.SetParameterBlockConstant(cam + kPoseParams);
    ordering->AddElementToGroup(cam, 1);
    ordering->AddElementToGroup(cam + kPoseParams, 1);
  }
  for (int k = 0; k < num_k; ++k)
    if (problem.HasParameterBlock(&x[template_offset + 3 * k]))
      ordering->AddElementToGroup(&x[template_offset + 3 * k], 1);
  for (int f = 0; f < num_frames; ++f)
    if (problem.HasParameterBlock(&x[pose_offset + kPoseParams * f]))
      ordering->AddElementToGroup(&x[pose_offset + kPoseParams * f], 0);
  for (int64_t i = 0; i < num_free; ++i) ordering->AddElementToGroup(&x[point_offset + 3 * i], 0);
  ARCO_ASSIGN_OR_RETURN(
      BundleAdjustmentSummary summary,
      SolveBundle(&problem, ordering, options.max_iterations, std::chrono::steady_clock::now()));

  // Back into the rig and the body; only options.cameras (the others stay exactly as given).
  for (int c : options.cameras) {
    Camera& cam = rig->cameras[c];
    const double* p = &x[c * kCameraStride];
    // The reference's pose exactly as given (not through angle-axis and back).
    if (c != options.reference_camera)
      ParamsToPose(p, &cam.cam_from_world.rotation, &cam.cam_from_world.translation);
    cam.fx = p[kPoseParams + kFx];
    cam.fy = p[kPoseParams + kFy];
  }
  for (int k = 0; k < num_k; ++k)
    if (body->points[k].allFinite()) body->points[k] = Eigen::Vector3d(&x[template_offset + 3 * k]);
  for (int f = 0; f < num_frames; ++f)
    ParamsToPose(&x[pose_offset + kPoseParams * f], &body->rotation[f], &body->translation[f]);
  return summary;
}

}  // namespace arco::calibration
