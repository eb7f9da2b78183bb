// The bow's pose from all views at once (track/bow_tracker.h's step 4): the bow is a
// segment of known length L, its pose the frog X (3) and a unit direction d (2 degrees of
// freedom, ceres::SphereManifold), the tip X + L d. One robust least-squares problem
// (Ceres, Levenberg-Marquardt) holds, per view:
//  - the stick's image line: the ideal (undistorted) projection of points along the
//    stick at their perpendicular distance to the view's fitted line (LSD segments);
//  - the stick's texture: the intensity of the view's frame at the distorted projection
//    (Camera::ProjectToPixel, autodiff) of X + u d for u along the stick, against the
//    labelled frame's at the same u, with a per-view brightness offset (direct
//    photometric alignment, as in Lucas-Kanade but over one shared 3D pose);
// and, weakly, the constant-velocity prediction of frog and tip and, when `arco detect`
// found it, the right hand at the frog.
// Why: each view alone fixes the stick's slide along its line only to a few millimetres
// (the texture's blocks are a couple of pixels), and triangulating frog and tip from
// two-view rays turns those disagreements into depth errors of tens of millimetres. Here
// no view's slide is decided alone: the depth is the one at which every view's texture
// lines up at once.
// Coarse to fine: the frames are blurred (Gaussian sigma per level) so the first level's
// basin is a few texture blocks wide; each level starts where the last ended.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "arco/camera/camera.h"

namespace arco::track {

// One view at one level of blur.
struct BowViewTerms {
  const Camera* camera = nullptr;
  // The stick's fitted image line (ideal pixels); line_weight 0: none.
  Eigen::Vector2d line_point = Eigen::Vector2d::Zero(), line_direction = Eigen::Vector2d::UnitX();
  double line_weight = 0;
  // The frame, blurred, in a box of the image (row-major floats, rows x cols, its first
  // pixel at x0, y0 of the image); nullptr: no texture term.
  const float* image = nullptr;
  int rows = 0, cols = 0, x0 = 0, y0 = 0;
  // Samples along the stick: u (mm from the frog) and the labelled frame's intensity.
  std::vector<double> u, value;
};

struct BowPointPrior {
  double u = 0;  // the point X + u d (0: frog, L: tip)
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  double sigma_mm = 0;  // 0: unused
};

struct BowSolveOptions {
  double line_sigma_px = 1;    // the line term's scale (Huber at this)
  double intensity_sigma = 8;  // grey levels (Huber at this)
  int line_points = 9;         // points along the stick for the line term
  int max_iterations = 30;
};

struct BowPose {
  Eigen::Vector3d frog = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  double cost = 0;      // the final cost (Ceres' 1/2 sum of robustified squares)
  bool usable = false;  // the solver ran and the pose is finite
};

// Refines `start` (frog, unit direction) on the terms. Deterministic: one thread, the
// terms in the given order.
BowPose SolveBowPose(const std::vector<BowViewTerms>& views,
                     const std::vector<BowPointPrior>& priors,
                     double length,
                     const BowPose& start,
                     const BowSolveOptions& options);

// The intensities (bicubic, as the solver sees them) of a box of a blurred image at the
// distorted projections of frog + u d; NaN where a point is behind the camera or within
// 2 pixels of the box's edge.
std::vector<double> SampleStick(const Camera& camera,
                                const float* image,
                                int rows,
                                int cols,
                                int x0,
                                int y0,
                                const Eigen::Vector3d& frog,
                                const Eigen::Vector3d& direction,
                                const std::vector<double>& u);

}  // namespace arco::track
