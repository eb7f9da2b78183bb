#include "arco/hand/ray_depth.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "arco/hand/fit.h"
#include "arco/util/dense_lm.h"
#include "arco/util/number_range.h"
#include "arco/util/stats.h"

namespace arco::hand {
namespace {

using DepthVector = Eigen::Matrix<double, kNumHandKeypoints, 1>;
using DepthMatrix = Eigen::Matrix<double, kNumHandKeypoints, kNumHandKeypoints>;

// A keypoint may not come nearer the camera than this along its ray.
constexpr double kMinDistanceMm = 1.0;

// The keypoints' distances t along their rays u from the centre c (p_k = c + t_k u_k):
// bones, targets and the stay prior, each residual over its sigma (header comment).
struct RayDepthProblem {
  const HandModel* model;
  const Eigen::Vector3d* centre;
  const std::array<Eigen::Vector3d, kNumHandKeypoints>* rays;
  const DepthVector* start;
  const std::vector<AxisTarget>* targets;
  const RayDepthOptions* options;

  double Evaluate(const DepthVector& t, DepthMatrix* h, DepthVector* g) const {
    h->setZero();
    g->setZero();
    double cost = 0;
    auto add = [&](double r, int i, double ji, int j, double jj) {
      cost += 0.5 * r * r;
      (*g)(i) += ji * r;
      (*h)(i, i) += ji * ji;
      if (j >= 0) {
        (*g)(j) += jj * r;
        (*h)(j, j) += jj * jj;
        (*h)(i, j) += ji * jj;
        (*h)(j, i) += ji * jj;
      }
    };
    const auto& u = *rays;
    for (int k = 1; k < kNumHandKeypoints; ++k) {
      const int p = ParentKeypoint(k);
      const Eigen::Vector3d v = t(k) * u[k] - t(p) * u[p];
      const double n = v.norm();
      if (!(n > 0)) continue;
      const double s = options->bone_sigma_mm;
      add((n - model->bone_length_mm(k)) / s, k, v.dot(u[k]) / (n * s), p, -v.dot(u[p]) / (n * s));
    }
    for (const AxisTarget& a : *targets) {
      const double r =
          (a.axis.dot(*centre + t(a.keypoint) * u[a.keypoint]) - a.coordinate_mm) / a.sigma_mm;
      add(r, a.keypoint, a.axis.dot(u[a.keypoint]) / a.sigma_mm, -1, 0);
    }
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      const double s = options->stay_sigma_mm;
      add((t(k) - (*start)(k)) / s, k, 1.0 / s, -1, 0);
    }
    return cost;
  }
  bool SolveDamped(DepthMatrix& damped, const DepthVector& g, DepthVector* step) const {
    const Eigen::LDLT<DepthMatrix> ldlt(damped);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return false;
    *step = -ldlt.solve(g);
    return step->allFinite();
  }
  void Plus(const DepthVector& t, const DepthVector& step, DepthVector* candidate) const {
    *candidate = (t + step).cwiseMax(kMinDistanceMm);
  }
};

}  // namespace

Status RayDepthOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(CheckInRange("bone_sigma_mm", bone_sigma_mm, AboveZero(100)));
  ARCO_RETURN_IF_ERROR(CheckInRange("stay_sigma_mm", stay_sigma_mm, AboveZero(1e4)));
  return CheckInRange("max_iterations", max_iterations, Closed(1, 1000));
}

std::optional<RayDepthResult> PlaceKeypointsAlongRays(const HandModel& model,
                                                      const Eigen::Vector3d& centre,
                                                      const HandPose& pose,
                                                      const std::vector<AxisTarget>& targets,
                                                      const RayDepthOptions& options) {
  if (!options.Validate().ok()) return std::nullopt;
  for (const AxisTarget& a : targets) {
    if (a.keypoint < 0 || a.keypoint >= kNumHandKeypoints || !(a.sigma_mm > 0) ||
        !std::isfinite(a.coordinate_mm) || !a.axis.allFinite() ||
        std::abs(a.axis.norm() - 1.0) > 1e-6)
      return std::nullopt;
  }
  const HandPointsMm points = ForwardKinematics(model, pose);
  std::array<Eigen::Vector3d, kNumHandKeypoints> rays;
  DepthVector start;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const Eigen::Vector3d d = points[k] - centre;
    start(k) = d.norm();
    if (!(start(k) > kMinDistanceMm) || !d.allFinite()) return std::nullopt;
    rays[k] = d / start(k);
  }
  RayDepthProblem problem{&model, &centre, &rays, &start, &targets, &options};
  DepthVector t = start;
  DenseLm<DepthVector, DepthMatrix> lm;
  DenseLmOptions lm_options;
  lm_options.max_iterations = options.max_iterations;
  const DenseLmSummary summary = lm.Minimize(problem, lm_options, &t);
  if (!std::isfinite(summary.final_cost)) return std::nullopt;
  HandPointsMm moved;
  std::vector<double> moves;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    moved[k] = centre + t(k) * rays[k];
    moves.push_back(std::abs(t(k) - start(k)));
  }
  const HandFit3dResult fit = FitHandToPoints3d(model, moved, HandFit3dOptions{}, pose);
  if (!fit.ok) return std::nullopt;
  RayDepthResult result;
  result.pose = fit.pose;
  result.median_move_mm = UpperMedian(moves);
  return result;
}

}  // namespace arco::hand
