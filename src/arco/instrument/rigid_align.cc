#include "arco/instrument/rigid_align.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "arco/geometry/alignment.h"

namespace arco {

// The spread check here is stricter than AlignPoints' own rank test: a near-collinear
// triple of noisy keypoints fixes the roll about its line only to noise / spread.
bool FitRigidSubset(const Eigen::Matrix3Xd& source,
                    const Eigen::Matrix3Xd& target,
                    const std::vector<int>& indices,
                    double min_spread,
                    RigidMatrix3d* target_from_source) {
  const int n = static_cast<int>(indices.size());
  if (n < 3) return false;
  Eigen::Vector3d s_mean = Eigen::Vector3d::Zero();
  for (int i : indices) s_mean += source.col(i);
  s_mean /= n;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  std::vector<Eigen::Vector3d> from(n), to(n);
  for (int j = 0; j < n; ++j) {
    const Eigen::Vector3d s = source.col(indices[j]) - s_mean;
    scatter += s * s.transpose();
    from[j] = source.col(indices[j]);
    to[j] = target.col(indices[j]);
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter, Eigen::EigenvaluesOnly);
  const double second = std::sqrt(std::max(0.0, eig.eigenvalues()(1)) / n);
  if (!(second >= min_spread)) return false;
  // Closed-form Kabsch/Umeyama solve (arco_geometry).
  const std::optional<AlignmentResult> fit = AlignPoints(from, to, {}, AlignmentOptions());
  if (!fit) return false;
  // Without scale, AlignPoints' similarity is this rigid map (scale 1).
  *target_from_source =
      RigidMatrix3d(fit->target_from_source.RotationMatrix(), fit->target_from_source.translation);
  return target_from_source->rotation.allFinite() && target_from_source->translation.allFinite();
}

namespace {

struct Hypothesis {
  RigidMatrix3d target_from_source;
  std::vector<int> inliers;
  double residual_sum = 0;
};

void Score(const Eigen::Matrix3Xd& source,
           const Eigen::Matrix3Xd& target,
           const std::vector<int>& common,
           double gate,
           Hypothesis* h) {
  h->inliers.clear();
  h->residual_sum = 0;
  for (int i : common) {
    const double r = (target.col(i) - (h->target_from_source * source.col(i))).norm();
    if (r <= gate) {
      h->inliers.push_back(i);
      h->residual_sum += r;
    }
  }
}

bool Better(const Hypothesis& a, const Hypothesis& b) {
  if (a.inliers.size() != b.inliers.size()) return a.inliers.size() > b.inliers.size();
  return a.residual_sum < b.residual_sum;
}

}  // namespace

RigidAlignment AlignRigidRobust(const Eigen::Matrix3Xd& source,
                                const Eigen::Matrix3Xd& target,
                                double gate,
                                double min_spread) {
  if (source.cols() != target.cols() || source.cols() > 32) {
    throw std::invalid_argument(
        "AlignRigidRobust: source and target need the same number of "
        "columns (at most 32)");
  }
  RigidAlignment out;
  std::vector<int> common;
  for (int i = 0; i < source.cols(); ++i) {
    if (source.col(i).allFinite() && target.col(i).allFinite()) common.push_back(i);
  }
  out.num_common = static_cast<int>(common.size());
  if (common.size() < 3) return out;

  Hypothesis best;
  bool have_best = false;
  if (FitRigidSubset(source, target, common, min_spread, &best.target_from_source)) {
    Score(source, target, common, gate, &best);
    have_best = true;
  }
  if (!have_best || best.inliers.size() < common.size()) {
    // Exhaustive minimal samples.
    Hypothesis h;
    std::vector<int> sample(3);
    const int n = static_cast<int>(common.size());
    for (int a = 0; a < n; ++a) {
      for (int b = a + 1; b < n; ++b) {
        for (int c = b + 1; c < n; ++c) {
          sample = {common[a], common[b], common[c]};
          if (!FitRigidSubset(source, target, sample, min_spread, &h.target_from_source)) {
            continue;
          }
          Score(source, target, common, gate, &h);
          if (!have_best || Better(h, best)) {
            best = h;
            have_best = true;
          }
        }
      }
    }
  }
  if (!have_best || best.inliers.size() < 3) return out;
  // Refit on the inliers, then re-select once with the refined pose.
  for (int round = 0; round < 2; ++round) {
    Hypothesis refit;
    if (!FitRigidSubset(source, target, best.inliers, min_spread, &refit.target_from_source)) {
      break;
    }
    Score(source, target, common, gate, &refit);
    if (refit.inliers.size() < 3) break;
    const bool same = refit.inliers == best.inliers;
    best = refit;
    if (same) break;
  }
  // Final least squares on the final inlier set (also checks it is not collinear).
  if (!FitRigidSubset(source, target, best.inliers, min_spread, &out.target_from_source)) {
    return out;
  }
  out.ok = true;
  double sum_sq = 0;
  for (int i : best.inliers) {
    out.inlier_mask |= (1u << i);
    sum_sq += (target.col(i) - out.target_from_source * source.col(i)).squaredNorm();
  }
  out.num_inliers = static_cast<int>(best.inliers.size());
  out.rms_residual = std::sqrt(sum_sq / out.num_inliers);
  return out;
}

}  // namespace arco
