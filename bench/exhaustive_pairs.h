// The SPD authors' triangulation, re-implemented as the benchmark baseline
// (DOMAIN.md section 2): keep views with score > 0.6; for every camera pair, an
// unweighted DLT in pixels (P = K [R | t], no undistortion, no normalisation); count
// the views whose reprojection error is below 60 px; keep the largest set (stop early
// when every view agrees); final unweighted DLT over that set. No cheirality, no
// refinement. Cost grows with the square of the number of views.
#pragma once

#include <Eigen/Core>
#include <Eigen/SVD>
#include <optional>
#include <vector>

#include "arco/camera/rig.h"

namespace arco::bench {

struct ExhaustivePairsOptions {
  double min_score = 0.6;
  double max_reprojection_px = 60.0;
};

// DLT via the SVD of A^T A, as their code does.
inline std::optional<Eigen::Vector3d> PixelDlt(const std::vector<Eigen::Matrix<double, 3, 4>>& p,
                                               const std::vector<Eigen::Vector2d>& x,
                                               const std::vector<int>& use) {
  if (use.size() < 2) return std::nullopt;
  Eigen::MatrixXd a(2 * use.size(), 4);
  for (size_t i = 0; i < use.size(); ++i) {
    a.row(2 * i) = x[use[i]].x() * p[use[i]].row(2) - p[use[i]].row(0);
    a.row(2 * i + 1) = x[use[i]].y() * p[use[i]].row(2) - p[use[i]].row(1);
  }
  const Eigen::Matrix4d q = a.transpose() * a;
  Eigen::JacobiSVD<Eigen::Matrix4d> svd(q, Eigen::ComputeFullU);
  const Eigen::Vector4d h = svd.matrixU().col(3);
  return Eigen::Vector3d(h.head<3>() / h[3]);
}

// One keypoint seen by views (pixel, score); `projections` are the cameras' K [R | t].
inline std::optional<Eigen::Vector3d> TriangulateExhaustivePairs(
    const std::vector<Eigen::Matrix<double, 3, 4>>& projections,
    const std::vector<Eigen::Vector2d>& pixels,
    const std::vector<double>& scores,
    const ExhaustivePairsOptions& o = {}) {
  std::vector<int> kept;
  for (size_t i = 0; i < pixels.size(); ++i) {
    if (scores[i] > o.min_score && pixels[i].allFinite()) kept.push_back(static_cast<int>(i));
  }
  if (kept.size() < 2) return std::nullopt;
  std::vector<int> best, inliers, pair(2);
  for (size_t a = 0; a < kept.size(); ++a) {
    for (size_t b = a + 1; b < kept.size(); ++b) {
      pair[0] = kept[a];
      pair[1] = kept[b];
      const auto x = PixelDlt(projections, pixels, pair);
      if (!x) continue;
      inliers.clear();
      for (int v : kept) {
        const Eigen::Vector3d h = projections[v] * x->homogeneous();
        if ((h.head<2>() / h.z() - pixels[v]).norm() < o.max_reprojection_px) inliers.push_back(v);
      }
      if (inliers.size() > best.size()) best = inliers;
      if (best.size() == kept.size()) break;
    }
    if (best.size() == kept.size()) break;
  }
  if (best.size() < 2) best = pair;  // their fallback: the last pair tried
  return PixelDlt(projections, pixels, best);
}

}  // namespace arco::bench
