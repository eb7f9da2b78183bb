// A rigid body's 6-DoF pose from 2D-3D correspondences in several calibrated cameras at
// once (a generalised PnP): RANSAC over small samples, each refined by Levenberg-Marquardt
// from the prediction, then robust LM (Huber) on the inliers of the best hypothesis, on
// arco's camera model with its distortion (camera/camera.h), through Ceres.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "arco/camera/camera.h"
#include "arco/geometry/transform.h"
#include "arco/util/number_range.h"
#include "arco/util/status.h"

namespace arco::track {

// One observation: a point of the body (its template frame) seen at a pixel of a camera.
struct PoseCorrespondence {
  int camera = 0;                     // index into the cameras given to SolveRigidPose
  Eigen::Vector3d point_in_template;  // the body's point in its template frame
  Eigen::Vector2d pixel;              // distorted pixel (OpenCV convention)
  double weight = 1;                  // > 0; labels and re-matched anchors weigh more
};

struct PoseSolverOptions {
  double inlier_px = 3.0;      // RANSAC gate on the reprojection error
  int ransac_trials = 24;      // samples tried (besides the prediction itself)
  int sample_size = 6;         // correspondences per sample (>= 3)
  double loss_scale_px = 1.5;  // Huber scale of the final refinement
  int max_iterations = 25;     // LM iterations of the final refinement
  // Pull towards the prediction, in pixels of reprojection per mm and per degree of
  // pose change (0: none): a weak temporal prior that keeps a pose defined when few
  // features remain.
  double prior_weight = 0.0;
  uint64_t seed = 0x74726b31;  // "trk1"
  Status Validate() const;
};

struct PoseSolution {
  Rigid3d world_from_template;
  std::vector<char> inlier;  // per correspondence
  int num_inliers = 0;
  double rms_px = 0;   // over the inliers
  int trials = 0;      // RANSAC hypotheses scored
  int iterations = 0;  // of the final refinement
  double initial_cost = 0, final_cost = 0;
  bool converged = false;
};

// Empty when fewer than `min_inliers` (>= 3) correspondences agree with any hypothesis.
// `prediction` starts every hypothesis (the previous frame's pose, extrapolated).
// Throws std::invalid_argument on invalid options or a camera index outside `cameras`.
std::optional<PoseSolution> SolveRigidPose(const std::vector<Camera>& cameras,
                                           const std::vector<PoseCorrespondence>& correspondences,
                                           const Rigid3d& prediction,
                                           const PoseSolverOptions& options,
                                           int min_inliers = 6);

}  // namespace arco::track
