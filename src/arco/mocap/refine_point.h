// Robust Levenberg-Marquardt refinement of one 3D point from its distorted
// reprojection errors in several views, with the soft-L1 loss
// rho(s) = 2 b^2 (sqrt(1 + s / b^2) - 1) (the loss Ceres calls SoftLOneLoss) on the
// squared pixel error s of each view.
//
// Three parameters and one residual pair per view, so the solver never stores the
// 2n x 3 Jacobian: one pass over the views accumulates the robust cost, the 3x3
// Gauss-Newton matrix J^T J and the gradient J^T r (closed-form Jacobians from
// Camera::ProjectWithJacobian), and the pass that tests a trial step is also the
// linearisation for the next one (ceres::TinySolver, used before, evaluated every
// accepted point twice, stored J and formed J^T J with a dynamic-size product; with the
// stopping rule below the refinement takes about a third of its CPU time in the
// triangulation bench, docs/performance.md). Does not allocate.
#pragma once

#include <Eigen/Core>

#include "arco/camera/camera.h"
#include "arco/util/status.h"

namespace arco {

struct RefinementView {
  const Camera* camera = nullptr;
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // observed, distorted (OpenCV convention)
  double sqrt_weight = 1.0;                         // multiplies the view's pixel residual
};

struct PointRefinementOptions {
  double loss_scale_px = 3.0;  // soft-L1 scale b: residuals beyond it count ~linearly
  int max_iterations = 20;     // linear solves (accepted or rejected steps)
  // Stop when |dx| <= parameter_tolerance (|x| + parameter_tolerance) ...
  double parameter_tolerance = 1e-10;
  // ... or when the linearised model predicts, or an accepted step achieves, a decrease
  // of the cost (sum of squared robust residuals, px^2) below this. 1e-4 px^2 stops
  // within a few micrometres of the minimum for an SPD-like rig (J^T J ~ 1e7 px^2/m^2),
  // far below the noise; the triangulation bench's errors move by 1e-4 mm.
  double function_tolerance_px2 = 1e-4;
  Status Validate() const;  // readable message on a bad value
};

struct PointRefinementSummary {
  double initial_cost = 0;  // sum over views of rho(|r|^2), px^2; +inf when behind a view
  double final_cost = 0;
  int iterations = 0;   // linear solves
  int evaluations = 0;  // passes over the views
};

// Refines `point_in_world` in place; `options` must pass Validate() (not re-checked per
// point). A trial step that puts the point behind any view
// is rejected (the cheirality the RANSAC stage established is kept). The cost never
// increases: final_cost <= initial_cost.
PointRefinementSummary RefinePointRobust(const RefinementView* views,
                                         int count,
                                         const PointRefinementOptions& options,
                                         Eigen::Vector3d* point_in_world);

}  // namespace arco
