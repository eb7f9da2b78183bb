// Robust multi-view triangulation of one keypoint:
//   1. keep views with a finite pixel and score >= min_score, undistort them
//      (PixelToNormalizedNewton, camera/undistort.h);
//   2. RANSAC over view pairs (geometry/robust.h schedule: most confident pairs first,
//      then seeded random pairs, at most max_ransac_trials, adaptive stop) with a pixel
//      gate and a cheirality test (the point must lie in front of both cameras);
//   3. confidence-weighted, conditioned DLT on the inliers, re-gated once;
//   4. Levenberg-Marquardt (refine_point.h, closed-form Jacobians through
//      Camera::ProjectWithJacobian) on the distorted reprojection error of the inliers
//      with a soft-L1 robust loss.
// Deterministic: views are ordered by (score, pixel) so results do not depend on the
// order of cameras in the rig, and the sampler is seeded.
//
// Errors in pixels follow the OpenCV convention of camera/camera.h; world units are
// those of the rig.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "arco/camera/rig.h"
#include "arco/geometry/triangulation.h"
#include "arco/mocap/refine_point.h"
#include "arco/util/json_io.h"
#include "arco/util/status.h"

namespace arco {

struct TriangulationOptions {
  double min_score = 0.3;             // detections below this confidence are ignored
  double max_reprojection_px = 15.0;  // RANSAC inlier gate (Pose2Sim uses 15 px)
  int max_ransac_trials = 40;         // view pairs tried at most (all pairs when fewer)
  double ransac_confidence = 0.999;   // adaptive stop: P(an all-inlier pair was tried)
  uint64_t seed = 0x61726330;         // sampler seed ("arc0")
  bool weight_by_score = true;        // DLT and refinement weight each view by its score
  bool refine = true;                 // robust Levenberg-Marquardt after RANSAC
  double robust_loss_scale_px = 3.0;  // soft-L1 loss scale: residuals beyond it count ~linearly
  int max_refine_iterations = 20;
  Status Validate() const;  // readable message on a bad value or combination
};

// Every field by its name (recorded with results).
Json ToJson(const TriangulationOptions& options);

// One 2D detection of the keypoint in one camera of the rig.
struct PointObservation {
  int camera = -1;        // index into Rig::cameras
  Eigen::Vector2d pixel;  // distorted pixel (OpenCV convention); NaN = missing
  double score = 1.0;     // detector confidence in [0, 1]; labels use 1
};

struct TriangulatedPoint {
  Eigen::Vector3d point_in_world = Eigen::Vector3d::Zero();
  std::vector<int> inlier_cameras;  // rig camera indices, ascending
  int num_views = 0;                // usable views (finite pixel, score >= min_score)
  double rms_reprojection_px = 0;   // over inlier views, with distortion
  bool refined = false;             // true when the LM refinement was accepted
};

// Per-thread working memory so the per-point call does not allocate in steady state
// (reuse one per thread; contents are internal).
struct TriangulationScratch {
  struct View {
    int camera;
    Eigen::Vector2d pixel;
    double score;
    Eigen::Vector2d normalized;  // undistorted, x = X/Z
    double focal_px;             // pixels per normalised unit, sqrt(fx fy)
  };
  std::vector<View> views;
  std::vector<char> inlier, best_inlier;
  std::vector<char> camera_seen;  // by rig camera: catches a camera observed twice
  std::vector<DltObservation> dlt;
  std::vector<RefinementView> refine;  // inlier views entering the refinement
};

// Immutable triangulation set-up for one rig: options are validated, projection
// matrices conditioned and pair schedules built once. Thread-safe const use.
class Triangulator {
 public:
  // Throws std::invalid_argument when options.Validate() fails or the rig is empty.
  Triangulator(const Rig& rig, const TriangulationOptions& options);

  // Empty when fewer than two usable views agree within the gate in front of the
  // cameras. Throws std::invalid_argument for a camera index outside the rig or a
  // camera observed twice (caller bugs).
  std::optional<TriangulatedPoint> Triangulate(const std::vector<PointObservation>& views,
                                               TriangulationScratch* scratch = nullptr) const;

  const Rig& rig() const { return rig_; }
  const TriangulationOptions& options() const { return options_; }

 private:
  Rig rig_;
  TriangulationOptions options_;
  WorldConditioning conditioning_;
  std::vector<Matrix34d> conditioned_cam_from_world_;  // [R|t] in conditioned world
  std::vector<double> focal_px_;  // sqrt(fx fy): pixels per normalised unit, by camera
  std::vector<std::vector<std::pair<int, int>>> pair_schedules_;  // by usable view count
};

// One-shot convenience (builds a Triangulator).
std::optional<TriangulatedPoint> TriangulateRobust(const Rig& rig,
                                                   const TriangulationOptions& options,
                                                   const std::vector<PointObservation>& views);

// Reprojection error (px) of a world point in one camera; +inf when behind it.
double ReprojectionErrorPx(const Camera& camera,
                           const Eigen::Vector3d& point_in_world,
                           const Eigen::Vector2d& pixel);

}  // namespace arco
