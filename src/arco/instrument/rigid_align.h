// Robust rigid alignment of a small point template to one frame's observations, used by
// the instrument template fit. Least squares (Kabsch/Umeyama without scale; Umeyama, IEEE
// PAMI 13(4) 1991) on all common points; when a residual exceeds the gate, every 3-point
// subset is tried as a hypothesis (at most C(9,3) = 84, exhaustive and so deterministic),
// the one with the most inliers (then the lowest inlier residual sum) wins and is refitted
// on its inliers.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "arco/geometry/transform.h"

namespace arco {

struct RigidAlignment {
  bool ok = false;  // false: fewer than 3 usable, non-collinear inlier points
  RigidMatrix3d target_from_source;  // target = R * source + t
  uint32_t inlier_mask = 0;  // bit k: point k used in the final fit
  int num_common = 0;        // points finite in both source and target
  int num_inliers = 0;
  double rms_residual = 0;  // over inliers, in the units of the points
};

// `source` and `target` have the same number of columns (at most 32); non-finite columns
// are missing. `gate` is the inlier threshold on |target - (R source + t)|; `min_spread`
// the smallest second singular value (same units) of the centred inlier source points
// below which they count as collinear.
RigidAlignment AlignRigidRobust(const Eigen::Matrix3Xd& source,
                                const Eigen::Matrix3Xd& target,
                                double gate,
                                double min_spread);

// Least-squares rigid fit (no scale) of the columns listed in `indices`; false when the
// points are collinear (second singular value of the centred source below min_spread).
bool FitRigidSubset(const Eigen::Matrix3Xd& source,
                    const Eigen::Matrix3Xd& target,
                    const std::vector<int>& indices,
                    double min_spread,
                    RigidMatrix3d* target_from_source);

}  // namespace arco
