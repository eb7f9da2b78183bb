#include "arco/mocap/triangulate_point.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "arco/camera/undistort.h"
#include "arco/geometry/robust.h"
#include "arco/mocap/refine_point.h"
#include "arco/mocap/refine_point_pixels.h"

namespace arco {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Squared undistorted-image error (px^2) of a conditioned point in one view; +inf
// behind it. Squared so the gate test and the MSAC cost need no square root.
double GateErrorSquaredPx2(const Matrix34d& conditioned_p,
                           const Eigen::Vector3d& x_conditioned,
                           const TriangulationScratch::View& v) {
  const Eigen::Vector3d h = conditioned_p * x_conditioned.homogeneous();
  if (!(h.z() > 0)) return kInf;
  return (h.head<2>() / h.z() - v.normalized).squaredNorm() * (v.focal_px * v.focal_px);
}

}  // namespace

Status TriangulationOptions::Validate() const {
  auto bad = [](const std::string& m) { return Status::Error("triangulation options: " + m); };
  if (!(min_score >= 0 && min_score <= 1)) return bad("min_score must be in [0, 1]");
  if (!(max_reprojection_px > 0 && std::isfinite(max_reprojection_px))) {
    return bad("max_reprojection_px must be a positive number");
  }
  if (max_ransac_trials < 1) return bad("max_ransac_trials must be >= 1");
  if (!(ransac_confidence > 0 && ransac_confidence < 1)) {
    return bad("ransac_confidence must be in (0, 1)");
  }
  if (!(robust_loss_scale_px > 0 && std::isfinite(robust_loss_scale_px))) {
    return bad("robust_loss_scale_px must be a positive number");
  }
  if (refine && max_refine_iterations < 1) {
    return bad("max_refine_iterations must be >= 1 when refine is on");
  }
  return Status::Ok();
}

double ReprojectionErrorPx(const Camera& camera,
                           const Eigen::Vector3d& point_in_world,
                           const Eigen::Vector2d& pixel) {
  const auto projected = camera.Project(point_in_world);
  if (!projected) return kInf;
  return (*projected - pixel).norm();
}

Triangulator::Triangulator(const Rig& rig, const TriangulationOptions& options)
    : rig_(rig), options_(options) {
  const Status status = options.Validate();
  if (!status.ok()) throw std::invalid_argument(status.message());
  if (rig.cameras.empty()) throw std::invalid_argument("Triangulator: the rig has no cameras");
  std::vector<Eigen::Vector3d> centers;
  for (const Camera& c : rig_.cameras) centers.push_back(c.CenterInWorld());
  conditioning_ = ConditioningFromCameraCenters(centers);
  for (const Camera& c : rig_.cameras) {
    focal_px_.push_back(std::sqrt(c.fx * c.fy));
    Matrix34d rt;
    rt.leftCols<3>() = c.cam_from_world.rotation;
    rt.col(3) = c.cam_from_world.translation;
    conditioned_cam_from_world_.push_back(ConditionProjection(rt, conditioning_));
  }
  const int n = static_cast<int>(rig_.cameras.size());
  pair_schedules_.resize(static_cast<size_t>(n) + 1);
  for (int k = 2; k <= n; ++k) {
    pair_schedules_[k] = MakePairSchedule(k, options_.max_ransac_trials, options_.seed);
  }
}

std::optional<TriangulatedPoint> Triangulator::Triangulate(
    const std::vector<PointObservation>& observations, TriangulationScratch* scratch_in) const {
  TriangulationScratch local;
  TriangulationScratch& s = scratch_in ? *scratch_in : local;
  const int num_cameras = static_cast<int>(rig_.cameras.size());

  // 1. Usable views, undistorted, in a camera-order independent order.
  s.views.clear();
  s.camera_seen.assign(static_cast<size_t>(num_cameras), 0);
  for (const PointObservation& o : observations) {
    if (o.camera < 0 || o.camera >= num_cameras) {
      throw std::invalid_argument("Triangulate: camera index " + std::to_string(o.camera) +
                                  " outside the rig");
    }
    if (!o.pixel.allFinite() || !(o.score >= options_.min_score)) continue;
    if (s.camera_seen[o.camera]++) {
      throw std::invalid_argument("Triangulate: camera " + std::to_string(o.camera) +
                                  " observed twice");
    }
    const Camera& cam = rig_.cameras[o.camera];
    s.views.push_back(
        {o.camera, o.pixel, o.score, PixelToNormalizedNewton(cam, o.pixel), focal_px_[o.camera]});
  }
  std::sort(s.views.begin(), s.views.end(), [](const auto& a, const auto& b) {
    if (a.score != b.score) return a.score > b.score;
    if (a.pixel.x() != b.pixel.x()) return a.pixel.x() < b.pixel.x();
    return a.pixel.y() < b.pixel.y();
  });
  const int n = static_cast<int>(s.views.size());
  if (n < 2) return std::nullopt;
  const double gate = options_.max_reprojection_px;
  const double gate2 = gate * gate;
  auto p_of = [&](int view) -> const Matrix34d& {
    return conditioned_cam_from_world_[s.views[view].camera];
  };

  // 2. RANSAC over pairs: most inliers wins, ties by the truncated (MSAC) cost.
  s.inlier.assign(n, 0);
  s.best_inlier.assign(n, 0);
  int best_count = 0;
  double best_cost = kInf;
  int64_t needed = std::numeric_limits<int64_t>::max();
  int64_t trial = 0;
  for (const auto& [a, b] : pair_schedules_[n]) {
    if (trial >= needed) break;
    ++trial;
    const auto x = TriangulateTwoViewsConditioned(
        p_of(a), s.views[a].normalized, p_of(b), s.views[b].normalized);
    if (!x) continue;
    int count = 0;
    double cost = 0;
    for (int k = 0; k < n; ++k) {
      const double e2 = GateErrorSquaredPx2(p_of(k), *x, s.views[k]);
      const bool in = e2 < gate2;
      s.inlier[k] = in;
      count += in;
      cost += in ? e2 : gate2;
    }
    if (!s.inlier[a] || !s.inlier[b]) continue;  // behind a sampled camera or inconsistent
    if (count > best_count || (count == best_count && cost < best_cost)) {
      best_count = count;
      best_cost = cost;
      s.best_inlier = s.inlier;
      if (best_count == n) break;
      needed =
          RansacTrialsNeeded(static_cast<double>(best_count) / n, 2, options_.ransac_confidence);
    }
  }
  if (best_count < 2) return std::nullopt;

  // 3. Weighted DLT on the inliers; re-gate against all views and solve once more
  //    when the consensus set changed (local optimisation, Chum et al. 2003).
  auto solve_inliers = [&](const std::vector<char>& in) -> std::optional<Eigen::Vector3d> {
    s.dlt.clear();
    for (int k = 0; k < n; ++k) {
      if (!in[k]) continue;
      const double w = (options_.weight_by_score ? s.views[k].score : 1.0) * s.views[k].focal_px;
      s.dlt.push_back({p_of(k), s.views[k].normalized, w});
    }
    DltOptions dlt;
    dlt.inhomogeneous = true;  // RANSAC's cheirality test keeps the points finite
    return TriangulateDltConditioned(s.dlt.data(), static_cast<int>(s.dlt.size()), dlt);
  };
  std::optional<Eigen::Vector3d> xc = solve_inliers(s.best_inlier);
  for (int round = 0; round < 2 && xc; ++round) {
    int count = 0;
    bool changed = false;
    for (int k = 0; k < n; ++k) {
      const bool in = GateErrorSquaredPx2(p_of(k), *xc, s.views[k]) < gate2;
      s.inlier[k] = in;
      count += in;
      changed |= (in != static_cast<bool>(s.best_inlier[k]));
    }
    if (!changed) break;
    if (count < 2) {
      xc.reset();
      break;
    }
    s.best_inlier = s.inlier;
    xc = solve_inliers(s.best_inlier);
  }
  if (!xc) return std::nullopt;
  Eigen::Vector3d x_world = conditioning_.center + conditioning_.scale * *xc;

  // 4. Robust Levenberg-Marquardt on the distorted reprojection error of the inliers
  //    (refine_point.h: 3 parameters, normal equations accumulated view by view).
  TriangulatedPoint result;
  // The refined views' pixels at the refined point, from the refinement's last pass
  // (refine_point_pixels.h); up to kCachedViews views, on the stack (a rig with more
  // projects them again below).
  constexpr int kCachedViews = 64;
  std::array<Eigen::Vector2d, 2 * kCachedViews> pixels;
  bool have_pixels = false;
  if (options_.refine) {
    s.refine.clear();
    for (int k = 0; k < n; ++k) {
      if (!s.best_inlier[k]) continue;
      const auto& v = s.views[k];
      s.refine.push_back(
          {&rig_.cameras[v.camera], v.pixel, options_.weight_by_score ? std::sqrt(v.score) : 1.0});
    }
    PointRefinementOptions refine;
    refine.loss_scale_px = options_.robust_loss_scale_px;
    refine.max_iterations = options_.max_refine_iterations;  // both checked by Validate()
    Eigen::Vector3d x = x_world;
    const int count = static_cast<int>(s.refine.size());
    PointRefinementSummary summary;
    const bool projected =
        internal::RefinePointRobustWithPixels(s.refine.data(),
                                              count,
                                              refine,
                                              &x,
                                              count <= kCachedViews ? pixels.data() : nullptr,
                                              &summary);
    if (x.allFinite() && summary.final_cost <= summary.initial_cost) {
      x_world = x;
      result.refined = true;
      have_pixels = projected && count <= kCachedViews;
    }
  }

  // Final classification with the true (distorted) projection.
  result.point_in_world = x_world;
  result.num_views = n;
  double sum_sq = 0;
  result.inlier_cameras.reserve(static_cast<size_t>(n));
  int refined_view = 0;  // index in s.refine (the best inliers, in k order)
  for (int k = 0; k < n; ++k) {
    const double e =
        have_pixels && s.best_inlier[k]
            ? (pixels[static_cast<size_t>(refined_view++)] - s.views[k].pixel).norm()
            : ReprojectionErrorPx(rig_.cameras[s.views[k].camera], x_world, s.views[k].pixel);
    if (e < gate) {
      result.inlier_cameras.push_back(s.views[k].camera);
      sum_sq += e * e;
    }
  }
  if (result.inlier_cameras.size() < 2) return std::nullopt;
  std::sort(result.inlier_cameras.begin(), result.inlier_cameras.end());
  result.rms_reprojection_px =
      std::sqrt(sum_sq / static_cast<double>(result.inlier_cameras.size()));
  return result;
}

std::optional<TriangulatedPoint> TriangulateRobust(const Rig& rig,
                                                   const TriangulationOptions& options,
                                                   const std::vector<PointObservation>& views) {
  return Triangulator(rig, options).Triangulate(views);
}

Json ToJson(const TriangulationOptions& o) {
  return {{"min_score", o.min_score},
          {"max_reprojection_px", o.max_reprojection_px},
          {"max_ransac_trials", o.max_ransac_trials},
          {"ransac_confidence", o.ransac_confidence},
          {"seed", o.seed},
          {"weight_by_score", o.weight_by_score},
          {"refine", o.refine},
          {"robust_loss_scale_px", o.robust_loss_scale_px},
          {"max_refine_iterations", o.max_refine_iterations}};
}

}  // namespace arco
