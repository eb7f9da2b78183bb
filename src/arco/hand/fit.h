// Fitting the hand model (wrist pose + 20 joint angles, fixed bone lengths,
// joint limits as parameter bounds) to observations:
//  - FitHandToPoints3d: IK-style fit to triangulated 3D keypoints (robust, mm);
//  - FitHandMultiView: all views' 2D keypoints at once, robust reprojection
//    loss, temporal prior from the previous frame, view gating.
// World coordinates are millimetres (cameras included). Frames whose input
// cannot support a fit come back flagged (ok = false, `problem` says why),
// never as a crash; the returned pose always respects the joint limits.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "arco/camera/camera.h"
#include "arco/hand/hand_model.h"
#include "arco/hand/kinematics.h"
#include "arco/util/status.h"

namespace arco::hand {

// One view's 2D hand: pixels in the camera's (distorted) image, OpenCV pixel
// convention; a keypoint is missing when its score is below the threshold or
// its pixel is not finite.
struct HandKeypoints2d {
  HandKeypoints2d() { pixels.fill(Eigen::Vector2d::Constant(std::nan(""))); }
  std::array<Eigen::Vector2d, kNumHandKeypoints> pixels;  // NaN until set
  std::array<double, kNumHandKeypoints> scores{};
};

struct HandFitOptions {
  double min_score = 0.3;          // keypoints below this score are ignored
  bool weight_by_score = true;     // residuals scaled by sqrt(score)
  double robust_loss_px = 6.0;     // Cauchy scale of the reprojection loss
  double view_gate_px = 12.0;      // trusted view: median residual <= this after solve 1
  int min_keypoints_per_view = 4;  // fewer -> the view is not used
  int min_views = 2;               // fewer usable / trusted views -> flagged frame
  double min_initial_points = 6;   // finite 3D points needed to initialise from 3D
  // Temporal prior towards the previous frame (residual units: px).
  double temporal_angle_weight_px_per_rad = 10.0;
  double temporal_rotation_weight_px_per_rad = 10.0;
  double temporal_translation_weight_px_per_mm = 0.2;
  int max_iterations = 50;
  Status Validate() const;
};

struct HandFitInit {
  // Triangulated keypoints in the world (mm); NaN entries are missing.
  std::optional<HandPointsMm> points_in_world_mm;
  // The previous frame's fitted pose: initialisation fallback and temporal prior.
  std::optional<HandPose> previous_pose;
};

struct HandFitResult {
  bool ok = false;                       // false: flagged frame, `problem` says why
  std::string problem;                   // empty when ok
  HandPose pose;                         // always within the joint limits
  std::string init_source;               // "points_3d", "previous", "triangulated" or "none"
  int num_views_with_hand = 0;           // views with >= min_keypoints_per_view keypoints
  std::vector<uint8_t> trusted_views;    // per view: 1 when it passed the gate
  std::vector<double> view_residual_px;  // per view median residual after solve 1 (NaN: unused)
  int num_observations = 0;              // keypoints in trusted views
  double rms_residual_px = 0;            // trusted keypoints, final pose
  double median_residual_px = 0;
  int iterations = 0;                       // both solves
  std::string termination;                  // Ceres' termination of the final solve
  double initial_cost = 0, final_cost = 0;  // final solve
};

struct HandFit3dOptions {
  double robust_loss_mm = 10.0;  // Cauchy scale
  int max_iterations = 100;
  Status Validate() const;
};

struct HandFit3dResult {
  bool ok = false;
  std::string problem;
  HandPose pose;
  int num_points = 0;
  double rms_error_mm = 0;  // over the finite input points
  int iterations = 0;
  std::string termination;
};

// Robust fit to 3D keypoints (NaN = missing). Initial pose `initial` when given
// and finite, else a rigid alignment of the palm points (wrist, thumb CMC, four
// MCPs) with the angles at zero.
HandFit3dResult FitHandToPoints3d(const HandModel& model,
                                  const HandPointsMm& points_in_world_mm,
                                  const HandFit3dOptions& options,
                                  const std::optional<HandPose>& initial = std::nullopt);

// Throws std::invalid_argument when cameras and views differ in size or the
// options are invalid.
HandFitResult FitHandMultiView(const HandModel& model,
                               const std::vector<Camera>& cameras,
                               const std::vector<HandKeypoints2d>& views,
                               const HandFitInit& init,
                               const HandFitOptions& options);

// Rigid wrist pose aligning the model's rest palm points (wrist, thumb CMC,
// four MCPs) to the finite ones among `points_in_world_mm`; empty with fewer
// than 3 finite, non-collinear palm points.
std::optional<HandPose> AlignPalm(const HandModel& model, const HandPointsMm& points_in_world_mm);

}  // namespace arco::hand
