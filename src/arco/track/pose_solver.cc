#include "arco/track/pose_solver.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace arco::track {
namespace {

// Pose = a change (angle-axis `delta_rotation`, `delta_translation`) of the prediction,
// rotating about the correspondences' centroid `centre`: well conditioned, no
// singularity at the start.
struct ReprojectionCost {
  const Camera* camera;
  Eigen::Vector3d predicted_minus_centre;  // prediction * point - centre
  Eigen::Vector3d centre;
  Eigen::Vector2d pixel;
  double weight;

  template <typename T>
  bool operator()(const T* delta_rotation, const T* delta_translation, T* residual) const {
    const T q[3] = {T(predicted_minus_centre.x()),
                    T(predicted_minus_centre.y()),
                    T(predicted_minus_centre.z())};
    T world[3];
    ceres::AngleAxisRotatePoint(delta_rotation, q, world);
    for (int i = 0; i < 3; ++i) world[i] += T(centre[i]) + delta_translation[i];
    T projected[2];
    if (!camera->ProjectToPixel(world, projected)) {
      residual[0] = residual[1] = T(1e3 * weight);  // behind the camera: a flat penalty
      return true;
    }
    residual[0] = T(weight) * (projected[0] - T(pixel.x()));
    residual[1] = T(weight) * (projected[1] - T(pixel.y()));
    return true;
  }
};

struct PriorCost {
  double weight;
  template <typename T>
  bool operator()(const T* delta_rotation, const T* delta_translation, T* residual) const {
    const double deg = 180.0 / M_PI;
    for (int i = 0; i < 3; ++i) {
      residual[i] = T(weight * deg) * delta_rotation[i];
      residual[3 + i] = T(weight) * delta_translation[i];
    }
    return true;
  }
};

class Problem {
 public:
  Problem(const std::vector<Camera>& cameras,
          const std::vector<PoseCorrespondence>& c,
          const Rigid3d& prediction)
      : cameras_(cameras), c_(c), prediction_(prediction) {
    centre_.setZero();
    for (const auto& x : c) centre_ += prediction * x.point_in_template;
    if (!c.empty()) centre_ /= static_cast<double>(c.size());
    moved_.reserve(c.size());
    for (const auto& x : c) moved_.push_back(prediction * x.point_in_template - centre_);
  }

  // world_from_template for a change of the prediction.
  Rigid3d Pose(const double* dr, const double* dt) const {
    Eigen::Vector3d axis(dr[0], dr[1], dr[2]);
    const double angle = axis.norm();
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
    if (angle > 0) q = Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis / angle));
    // x -> q (R0 x + t0 - c) + c + dt
    const Rigid3d change(q, centre_ + Eigen::Vector3d(dt[0], dt[1], dt[2]) - q * centre_);
    return change * prediction_;
  }

  // Levenberg-Marquardt over the correspondences `use`, starting at (dr, dt).
  ceres::Solver::Summary Refine(const std::vector<int>& use,
                                double loss_scale_px,
                                double prior_weight,
                                int max_iterations,
                                double* dr,
                                double* dt) const {
    ceres::Problem::Options po;
    ceres::Problem problem(po);
    for (int i : use) {
      const auto& x = c_[i];
      auto* cost = new ceres::AutoDiffCostFunction<ReprojectionCost, 2, 3, 3>(
          new ReprojectionCost{&cameras_[x.camera], moved_[i], centre_, x.pixel, x.weight});
      ceres::LossFunction* loss =
          loss_scale_px > 0 ? new ceres::HuberLoss(loss_scale_px * x.weight) : nullptr;
      problem.AddResidualBlock(cost, loss, dr, dt);
    }
    if (prior_weight > 0) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<PriorCost, 6, 3, 3>(new PriorCost{prior_weight}),
          nullptr,
          dr,
          dt);
    }
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::DENSE_QR;
    so.max_num_iterations = max_iterations;
    so.num_threads = 1;
    so.logging_type = ceres::SILENT;
    so.minimizer_progress_to_stdout = false;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    return summary;
  }

  double ErrorPx(const Rigid3d& pose, int i) const {
    const auto& x = c_[i];
    const auto p = cameras_[x.camera].Project(pose * x.point_in_template);
    if (!p) return std::numeric_limits<double>::infinity();
    return (*p - x.pixel).norm();
  }

 private:
  const std::vector<Camera>& cameras_;
  const std::vector<PoseCorrespondence>& c_;
  Rigid3d prediction_;
  Eigen::Vector3d centre_;
  std::vector<Eigen::Vector3d> moved_;
};

}  // namespace

Status PoseSolverOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(CheckInRange("inlier_px", inlier_px, AboveZero(1000)));
  ARCO_RETURN_IF_ERROR(CheckInRange("ransac_trials", ransac_trials, Closed(0, 10000)));
  ARCO_RETURN_IF_ERROR(CheckInRange("sample_size", sample_size, Closed(3, 1000)));
  ARCO_RETURN_IF_ERROR(CheckInRange("loss_scale_px", loss_scale_px, Closed(0, 1000)));
  ARCO_RETURN_IF_ERROR(CheckInRange("max_iterations", max_iterations, Closed(1, 1000)));
  ARCO_RETURN_IF_ERROR(CheckInRange("prior_weight", prior_weight, Closed(0, 1e6)));
  return Status::Ok();
}

std::optional<PoseSolution> SolveRigidPose(const std::vector<Camera>& cameras,
                                           const std::vector<PoseCorrespondence>& correspondences,
                                           const Rigid3d& prediction,
                                           const PoseSolverOptions& options,
                                           int min_inliers) {
  const Status valid = options.Validate();
  if (!valid.ok()) throw std::invalid_argument("PoseSolverOptions: " + valid.message());
  for (const auto& c : correspondences) {
    if (c.camera < 0 || c.camera >= static_cast<int>(cameras.size())) {
      throw std::invalid_argument("SolveRigidPose: camera index " + std::to_string(c.camera) +
                                  " outside the " + std::to_string(cameras.size()) + " cameras");
    }
    if (!(c.weight > 0)) throw std::invalid_argument("SolveRigidPose: weight must be > 0");
  }
  min_inliers = std::max(3, min_inliers);
  const int n = static_cast<int>(correspondences.size());
  if (n < min_inliers) return std::nullopt;
  const Problem problem(cameras, correspondences, prediction);
  const double gate = options.inlier_px;

  // MSAC score of a pose (lower is better) and its inliers.
  const auto score = [&](const Rigid3d& pose, std::vector<char>* inlier) {
    double cost = 0;
    int count = 0;
    inlier->assign(n, 0);
    for (int i = 0; i < n; ++i) {
      const double e = problem.ErrorPx(pose, i);
      const double w = correspondences[i].weight;
      if (e < gate) {
        (*inlier)[i] = 1;
        ++count;
        cost += w * e * e;
      } else {
        cost += w * gate * gate;
      }
    }
    return std::make_pair(count, cost);
  };

  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  double best_dr[3] = {0, 0, 0}, best_dt[3] = {0, 0, 0};
  std::vector<char> inlier, best_inlier;
  double best_cost = std::numeric_limits<double>::infinity();
  int trials = 0;
  // Hypothesis 0: the prediction itself, and the prediction refined robustly on all.
  {
    const auto s = score(problem.Pose(best_dr, best_dt), &inlier);
    best_cost = s.second;
    best_inlier = inlier;
    ++trials;
    double dr[3] = {0, 0, 0}, dt[3] = {0, 0, 0};
    problem.Refine(all, options.loss_scale_px, 0, 10, dr, dt);
    const auto r = score(problem.Pose(dr, dt), &inlier);
    ++trials;
    if (r.second < best_cost) {
      best_cost = r.second;
      best_inlier = inlier;
      std::copy(dr, dr + 3, best_dr);
      std::copy(dt, dt + 3, best_dt);
    }
  }
  std::mt19937_64 rng(options.seed);
  const int k = std::min(options.sample_size, n);
  std::vector<int> sample;
  for (int t = 0; t < options.ransac_trials && n > k; ++t) {
    sample.clear();
    while (static_cast<int>(sample.size()) < k) {
      const int i = static_cast<int>(rng() % static_cast<uint64_t>(n));
      if (std::find(sample.begin(), sample.end(), i) == sample.end()) sample.push_back(i);
    }
    double dr[3] = {0, 0, 0}, dt[3] = {0, 0, 0};
    problem.Refine(sample, 0, 0, 8, dr, dt);
    const auto r = score(problem.Pose(dr, dt), &inlier);
    ++trials;
    if (r.second < best_cost) {
      best_cost = r.second;
      best_inlier = inlier;
      std::copy(dr, dr + 3, best_dr);
      std::copy(dt, dt + 3, best_dt);
    }
  }

  // Robust refinement on the best hypothesis' inliers, twice (inliers recomputed).
  PoseSolution solution;
  solution.trials = trials;
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<int> use;
    for (int i = 0; i < n; ++i)
      if (best_inlier[i]) use.push_back(i);
    if (static_cast<int>(use.size()) < min_inliers) return std::nullopt;
    const ceres::Solver::Summary s = problem.Refine(
        use, options.loss_scale_px, options.prior_weight, options.max_iterations, best_dr, best_dt);
    if (pass == 0) solution.initial_cost = s.initial_cost;
    solution.final_cost = s.final_cost;
    solution.iterations += static_cast<int>(s.iterations.size());
    solution.converged = s.termination_type == ceres::CONVERGENCE;
    score(problem.Pose(best_dr, best_dt), &best_inlier);
  }
  solution.world_from_template = problem.Pose(best_dr, best_dt);
  solution.inlier = best_inlier;
  double sum2 = 0;
  for (int i = 0; i < n; ++i) {
    if (!best_inlier[i]) continue;
    const double e = problem.ErrorPx(solution.world_from_template, i);
    sum2 += e * e;
    ++solution.num_inliers;
  }
  if (solution.num_inliers < min_inliers) return std::nullopt;
  solution.rms_px = std::sqrt(sum2 / solution.num_inliers);
  return solution;
}

}  // namespace arco::track
