// The bundle adjustment of a rig over points seen by its cameras, without a board: what
// `arco calibrate refine` (calibrate/calibration_refine.h) solves in each of its passes on
// the performer's keypoints and the instrument (docs/calibration.md "Refining with the
// performer"). The caller finds the points (triangulation, gating, the instrument's fit);
// this solves for them and the rig.
//
// Unknowns: every camera's pose (cam_from_world), optionally fx and fy; one 3D point per
// free track; a rigid body: its template points in its own frame, shared by all frames,
// and one pose (world_from_body) per frame.
// Residuals: reprojection of every observation through arco's camera model
// (reprojection_cost.h: PixelFromPointInCamera, distortion included) under a robust loss;
// plus one residual that holds the distance between the midpoints of two pairs of template
// points (the instrument's nut and bridge centres) at a given length: the only residual
// that sees the scale.
// Gauge: the reference camera's pose is held fixed; the scale comes from the length.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "arco/camera/rig.h"
#include "arco/util/status.h"

namespace arco::calibration {

// What one Ceres solve reports (both adjustments: the board rig's and this one).
struct BundleAdjustmentSummary {
  std::string termination;  // Ceres's termination type ("CONVERGENCE", "NO_CONVERGENCE", ...)
  int iterations = 0;
  double initial_cost = 0, final_cost = 0;
  int residual_blocks = 0;
  int board_poses = 0;  // the board rig's adjustment only
  double time_s = 0;
};

struct BundleObservation {
  int camera = 0;  // rig index
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
};

// One point in one frame with the views that see it.
struct BundleTrack {
  int frame = 0;   // the rigid body's pose index (and the caller's frame)
  int point = 0;   // the caller's id of the point (e.g. its layout column); not read here
  int rigid = -1;  // template point index of the rigid body, -1 = a free point
  Eigen::Vector3d point_in_world = Eigen::Vector3d::Zero();  // start of a free point
  std::vector<BundleObservation> observations;
};

// A rigid body: template points (world units, body frame; NaN = not in the template) and a
// pose per frame (valid[f] false = none: its tracks must not be rigid).
struct RigidBody {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Matrix3d> rotation;  // world_from_body
  std::vector<Eigen::Vector3d> translation;
  std::vector<char> valid;
};

// |mid(a0, a1) - mid(b0, b1)| = length for four template points, with the residual
// multiplied by weight (met exactly at the optimum whatever the weight, which only
// conditions the problem).
struct MidpointDistance {
  int a0 = -1, a1 = -1, b0 = -1, b1 = -1;
  double length = 0;  // world units
  double weight = 1;
};

enum class BundleLoss { kCauchy, kHuber };

struct RigAdjustmentOptions {
  int reference_camera = 0;  // rig index: its pose is held fixed (the gauge)
  // Rig indices of the cameras written back; the others stay exactly as given.
  std::vector<int> cameras;
  bool refine_focal = false;  // also fx, fy of every camera (else the intrinsics are held)
  // Cauchy while gross errors may remain; Huber once a gate has removed them (Cauchy's
  // down-weighting near the noise level can make the reduced system indefinite).
  BundleLoss loss = BundleLoss::kHuber;
  double loss_scale_px = 2;
  int max_iterations = 100;
  MidpointDistance scale;  // template indices into body.points
  // Indices within the rig and the body's template, loss_scale_px finite > 0,
  // max_iterations >= 1, the scale's length and weight finite > 0.
  Status Validate(int num_cameras, int num_template_points) const;
};

// Adjusts `rig` (the poses of options.cameras but the reference's, and fx, fy with
// refine_focal) and `body` (template points and poses) to the tracks; a free track's point
// is solved for but not returned. Errors: invalid options (Validate), a track whose camera,
// template point or frame is not the rig's or the body's, Ceres's failure. On an error rig
// and body are unchanged.
StatusOr<BundleAdjustmentSummary> AdjustRig(const RigAdjustmentOptions& options,
                                            const std::vector<BundleTrack>& tracks,
                                            Rig* rig,
                                            RigidBody* body);

}  // namespace arco::calibration
