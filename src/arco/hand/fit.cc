#include "arco/hand/fit.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "arco/geometry/alignment.h"
#include "arco/geometry/triangulation.h"
#include "arco/hand/fit_costs.h"
#include "arco/util/dense_lm.h"
#include "arco/util/stats.h"

namespace arco::hand {
namespace {

using internal::PixelObservation;
using internal::ReprojectionResiduals;
using internal::TemporalResiduals;

constexpr int kPalmKeypoints[6] = {0, 1, 5, 9, 13, 17};
const double kNaN = std::nan("");

// A pose as the fits' parameters: wrist angle-axis, wrist position mm, 20 angles.
using PoseVector = Eigen::Matrix<double, 6 + kNumJointDofs, 1>;
PoseVector ToVector(const HandPose& pose) {
  PoseVector x;
  x.head<6>() << pose.WristAngleAxis(), pose.world_from_wrist.translation;
  std::copy(pose.angles_rad.begin(), pose.angles_rad.end(), x.data() + 6);
  return x;
}
HandPose ToPose(const HandModel& model, const PoseVector& x) {
  HandPose pose;
  pose.SetWristAngleAxis(x.head<3>());
  pose.world_from_wrist.translation = x.segment<3>(3);
  std::copy(x.data() + 6, x.data() + 6 + kNumJointDofs, pose.angles_rad.begin());
  return ClampToLimits(model, pose);  // the solver keeps bounds; this guards rounding
}

// A relative cost change of 1e-5 ends the solve. 1e-10 (until issue 16) took twice the
// iterations of Ceres' default 1e-6; 1e-5 takes a quarter fewer again (per frame of the
// one-minute 20-camera take: 17 -> 12.5 iterations in solve 1, 28 -> 24 in the 3D
// initialisation) for changes far below the keypoints' noise: docs/accuracy.md's
// table (seed 0) within 0.01 mm on average per method and setting. 1e-4 halves solve
// 1 again but moved the arco method's harsh contact deviation by +0.04 mm
// (docs/performance.md, issue 28 part 3).
constexpr double kFunctionTolerance = 1e-5;
constexpr double kParameterTolerance = 1e-8;

DenseLmOptions LmOptions(int max_iterations) {
  DenseLmOptions options;
  options.max_iterations = max_iterations;
  options.function_tolerance = kFunctionTolerance;
  options.parameter_tolerance = kParameterTolerance;
  options.keep_last_step = false;
  return options;
}

bool Usable(const HandKeypoints2d& view, int k, double min_score) {
  return view.scores[k] >= min_score && view.pixels[k].allFinite();
}

// Unweighted pixel error of every observation at `pose` (inf when behind).
std::vector<double> PixelErrors(const HandModel& model,
                                const HandPose& pose,
                                const std::vector<PixelObservation>& observations) {
  const HandPointsMm points = ForwardKinematics(model, pose);
  std::vector<double> errors(observations.size());
  for (size_t i = 0; i < observations.size(); ++i) {
    const auto& o = observations[i];
    const auto px = o.camera->Project(points[o.keypoint]);
    errors[i] = px ? (*px - o.pixel).norm() : INFINITY;
  }
  return errors;
}

// Linear triangulation of each keypoint over the usable views (init only; the
// robust fits that follow absorb outlier views).
HandPointsMm TriangulateKeypoints(const std::vector<Camera>& cameras,
                                  const std::vector<HandKeypoints2d>& views,
                                  const std::vector<uint8_t>& usable_view,
                                  double min_score) {
  std::vector<Eigen::Vector3d> centers;
  for (const Camera& c : cameras) centers.push_back(c.CenterInWorld());
  const WorldConditioning conditioning = ConditioningFromCameraCenters(centers);
  HandPointsMm points;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    std::vector<DltObservation> obs;
    for (size_t v = 0; v < views.size(); ++v) {
      if (!usable_view[v] || !Usable(views[v], k, min_score)) continue;
      DltObservation o;
      o.projection << cameras[v].cam_from_world.rotation, cameras[v].cam_from_world.translation;
      o.point = cameras[v].PixelToNormalized(views[v].pixels[k]);
      o.weight = views[v].scores[k];
      obs.push_back(o);
    }
    const auto p = TriangulateDlt(obs, conditioning);
    points[k] = p ? *p : Eigen::Vector3d::Constant(kNaN);
  }
  return points;
}

}  // namespace

Status HandFitOptions::Validate() const {
  auto bad = [](const std::string& m) { return Status::Error("HandFitOptions: " + m); };
  if (!(min_score >= 0 && min_score <= 1)) return bad("min_score must be in [0, 1]");
  if (!(robust_loss_px > 0)) return bad("robust_loss_px must be > 0");
  if (!(view_gate_px > 0)) return bad("view_gate_px must be > 0");
  if (min_keypoints_per_view < 1) return bad("min_keypoints_per_view must be >= 1");
  if (min_views < 1) return bad("min_views must be >= 1");
  if (min_initial_points < 3) return bad("min_initial_points must be >= 3");
  if (!(temporal_angle_weight_px_per_rad >= 0) || !(temporal_rotation_weight_px_per_rad >= 0) ||
      !(temporal_translation_weight_px_per_mm >= 0)) {
    return bad("temporal weights must be >= 0");
  }
  if (max_iterations < 1) return bad("max_iterations must be >= 1");
  return Status::Ok();
}

Status HandFit3dOptions::Validate() const {
  if (!(robust_loss_mm > 0)) return Status::Error("HandFit3dOptions: robust_loss_mm must be > 0");
  if (max_iterations < 1) return Status::Error("HandFit3dOptions: max_iterations must be >= 1");
  return Status::Ok();
}

std::optional<HandPose> AlignPalm(const HandModel& model, const HandPointsMm& points_in_world_mm) {
  std::vector<Eigen::Vector3d> source, target;
  for (int k : kPalmKeypoints) {
    if (!points_in_world_mm[k].allFinite()) continue;
    source.push_back(model.rest_point_mm(k));
    target.push_back(points_in_world_mm[k]);
  }
  if (source.size() < 3) return std::nullopt;
  // Nullopt for coincident or collinear palm points (rotation undetermined).
  const std::optional<AlignmentResult> fit = AlignPoints(source, target, {}, AlignmentOptions{});
  if (!fit) return std::nullopt;
  HandPose pose;
  pose.world_from_wrist.rotation = fit->target_from_source.RotationMatrix();
  pose.world_from_wrist.translation = fit->target_from_source.translation;
  return pose;
}

HandFit3dResult FitHandToPoints3d(const HandModel& model,
                                  const HandPointsMm& points_in_world_mm,
                                  const HandFit3dOptions& options,
                                  const std::optional<HandPose>& initial) {
  const Status valid = options.Validate();
  if (!valid.ok()) throw std::invalid_argument(valid.message());
  HandFit3dResult result;
  for (const auto& p : points_in_world_mm) result.num_points += p.allFinite();
  std::optional<HandPose> start;
  if (initial && initial->world_from_wrist.rotation.allFinite() &&
      initial->world_from_wrist.translation.allFinite()) {
    start = initial;
  } else {
    start = AlignPalm(model, points_in_world_mm);
  }
  if (!start || result.num_points < 3) {
    result.problem = "fewer than 3 usable (finite, non-collinear) palm points to initialise from";
    result.pose = ClampToLimits(model, HandPose{});
    return result;
  }
  PoseVector x = ToVector(ClampToLimits(model, *start));
  const double c = options.robust_loss_mm;
  internal::PointProblem problem({&model, &points_in_world_mm, c * c}, nullptr);
  DenseLm<PoseVector, internal::PointProblem::Matrix> lm;
  const DenseLmSummary summary = lm.Minimize(problem, LmOptions(options.max_iterations), &x);
  result.pose = ToPose(model, x);
  result.iterations = 1 + summary.steps;  // as Ceres counted: the start and each step
  result.termination = summary.converged ? "CONVERGENCE" : "NO_CONVERGENCE";
  const HandPointsMm fitted = ForwardKinematics(model, result.pose);
  double sum2 = 0;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    if (points_in_world_mm[k].allFinite())
      sum2 += (fitted[k] - points_in_world_mm[k]).squaredNorm();
  }
  result.rms_error_mm = std::sqrt(sum2 / result.num_points);
  result.ok = std::isfinite(summary.final_cost);
  if (!result.ok) result.problem = "solver failed: the cost is not finite";
  return result;
}

HandFitResult FitHandMultiView(const HandModel& model,
                               const std::vector<Camera>& cameras,
                               const std::vector<HandKeypoints2d>& views,
                               const HandFitInit& init,
                               const HandFitOptions& options) {
  if (cameras.size() != views.size()) {
    throw std::invalid_argument("FitHandMultiView: " + std::to_string(cameras.size()) +
                                " cameras but " + std::to_string(views.size()) + " views");
  }
  const Status valid = options.Validate();
  if (!valid.ok()) throw std::invalid_argument(valid.message());
  const int num_views = static_cast<int>(views.size());
  HandFitResult result;
  result.init_source = "none";
  result.trusted_views.assign(num_views, 0);
  result.view_residual_px.assign(num_views, kNaN);
  result.pose = ClampToLimits(model, init.previous_pose.value_or(HandPose{}));
  const bool has_previous = init.previous_pose.has_value() &&
                            init.previous_pose->world_from_wrist.rotation.allFinite() &&
                            init.previous_pose->world_from_wrist.translation.allFinite();

  std::vector<uint8_t> usable(num_views, 0);
  for (int v = 0; v < num_views; ++v) {
    int count = 0;
    for (int k = 0; k < kNumHandKeypoints; ++k) count += Usable(views[v], k, options.min_score);
    usable[v] = count >= options.min_keypoints_per_view;
    result.num_views_with_hand += usable[v];
  }
  if (result.num_views_with_hand < options.min_views) {
    std::ostringstream msg;
    msg << "hand seen in " << result.num_views_with_hand << " views (need " << options.min_views
        << " with >= " << options.min_keypoints_per_view << " keypoints)";
    result.problem = msg.str();
    return result;
  }

  // Initialisation: given 3D points, else the previous frame, else our own DLT.
  std::optional<HandPose> start;
  auto from_points = [&](const HandPointsMm& points, const char* source) {
    int finite = 0;
    for (const auto& p : points) finite += p.allFinite();
    if (finite < options.min_initial_points) return;
    const HandFit3dResult fit3d = FitHandToPoints3d(model, points, HandFit3dOptions{});
    if (fit3d.ok) start = fit3d.pose, result.init_source = source;
  };
  if (init.points_in_world_mm) from_points(*init.points_in_world_mm, "points_3d");
  if (!start && has_previous)
    start = ClampToLimits(model, *init.previous_pose), result.init_source = "previous";
  if (!start)
    from_points(TriangulateKeypoints(cameras, views, usable, options.min_score), "triangulated");
  if (!start) {
    result.problem = "no initialisation (no usable 3D points, previous pose or triangulation)";
    return result;
  }

  using internal::ReprojectionProblem;
  PoseVector x = ToVector(*start);
  std::optional<TemporalResiduals> temporal;
  if (has_previous) {
    const HandPose& prev = *init.previous_pose;
    temporal = TemporalResiduals{prev.world_from_wrist.rotation,
                                 prev.world_from_wrist.translation,
                                 ClampToLimits(model, prev).angles_rad,
                                 options.temporal_rotation_weight_px_per_rad,
                                 options.temporal_translation_weight_px_per_mm,
                                 options.temporal_angle_weight_px_per_rad};
  }
  DenseLm<PoseVector, ReprojectionProblem::Matrix> lm;
  const DenseLmOptions lm_options = LmOptions(options.max_iterations);
  auto solve = [&](const std::vector<PixelObservation>& observations) {
    const double c = options.robust_loss_px;
    ReprojectionProblem problem({&model, &observations, c * c}, temporal ? &*temporal : nullptr);
    return lm.Minimize(problem, lm_options, &x);
  };
  auto collect = [&](const std::vector<uint8_t>& use) {
    std::vector<PixelObservation> obs;
    for (int v = 0; v < num_views; ++v) {
      if (!use[v]) continue;
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        if (!Usable(views[v], k, options.min_score)) continue;
        obs.push_back(
            {&cameras[v],
             v,
             k,
             views[v].pixels[k],
             options.weight_by_score ? std::sqrt(std::min(views[v].scores[k], 1.0)) : 1.0});
      }
    }
    return obs;
  };

  // Solve 1: every usable view, robust loss. Then gate views on their median
  // residual and solve again with the trusted ones.
  std::vector<PixelObservation> observations = collect(usable);
  DenseLmSummary summary = solve(observations);
  result.iterations = 1 + summary.steps;  // as Ceres counted: the start and each step
  HandPose pose = ToPose(model, x);
  std::vector<double> errors = PixelErrors(model, pose, observations);
  std::vector<std::vector<double>> per_view(num_views);
  for (size_t i = 0; i < observations.size(); ++i)
    per_view[observations[i].view].push_back(errors[i]);
  int trusted = 0;
  for (int v = 0; v < num_views; ++v) {
    if (!usable[v]) continue;
    result.view_residual_px[v] = UpperMedian(per_view[v]);
    result.trusted_views[v] = result.view_residual_px[v] <= options.view_gate_px;
    trusted += result.trusted_views[v];
  }
  if (trusted != result.num_views_with_hand && trusted > 0) {
    observations = collect(result.trusted_views);
    summary = solve(observations);
    result.iterations += 1 + summary.steps;
    pose = ToPose(model, x);
    errors = PixelErrors(model, pose, observations);
  }
  result.pose = pose;
  result.termination = summary.converged ? "CONVERGENCE" : "NO_CONVERGENCE";
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.num_observations = static_cast<int>(observations.size());
  double sum2 = 0;
  for (double e : errors) sum2 += e * e;
  result.rms_residual_px = errors.empty() ? kNaN : std::sqrt(sum2 / errors.size());
  result.median_residual_px = UpperMedian(errors);
  if (trusted < options.min_views) {
    std::ostringstream msg;
    msg << "only " << trusted << " of " << result.num_views_with_hand << " views agree within "
        << options.view_gate_px << " px";
    result.problem = msg.str();
  } else if (!std::isfinite(summary.final_cost)) {
    result.problem = "solver failed: the cost is not finite";
  } else {
    result.ok = true;
  }
  return result;
}

}  // namespace arco::hand
