// Where the synthetic performer sits inside a camera rig.
//
// The rig is first scaled to millimetres (ScaleRigToMm). The stage then finds
//   - the focus: the point nearest (least squares) to all optical axes,
//   - up: the mean of the cameras' "up" directions (-y of each camera, since
//     image rows grow downwards in every calibrated view),
//   - forward: the horizontal mean direction from the focus to the cameras
//     (the performer faces the cameras; most rigs film the player from the front),
// and places the performer frame there.
//
// Performer frame (mm): origin on the seat between the hips, x to the
// performer's LEFT, y up, z forward (x cross y = z, right-handed).
#pragma once

#include <Eigen/Core>

#include "arco/camera/rig.h"
#include "arco/geometry/transform.h"
#include "arco/util/status.h"

namespace arco::synth {

struct StageOptions {
  // Millimetres per world unit of the calibration; 0 = automatic: 1 for "mm",
  // 1000 for "m", else camera_distance_mm / median camera-to-focus distance.
  double mm_per_unit = 0;
  // Median camera distance assumed for calibrations in arbitrary units. The
  // default reproduces the SPD cello_1113_scale rig's metric scale (about 2020
  // mm per Metashape unit, from the 695 mm nut-bridge distance).
  double camera_distance_mm = 0;  // 0 = kSpdCameraDistanceMm
  // Performer-frame point placed at the focus (roughly the instrument's middle).
  Eigen::Vector3d focus_in_performer_mm{60, 380, 200};
  Status Validate() const;
};

// Median camera-to-focus distance of the SPD rig in mm (see StageOptions).
extern const double kSpdCameraDistanceMm;

struct Stage {
  double mm_per_unit = 1;
  Eigen::Vector3d focus_in_world_mm = Eigen::Vector3d::Zero();
  // The performer frame in the world (mm): the rotation's columns are performer x
  // (left), y (up), z (forward) in the world, the translation the performer's origin. A
  // matrix rotation: synth's numbers are matrix products (docs/architecture.md).
  RigidMatrix3d world_from_performer;
  double median_camera_distance_mm = 0;
};

// Copy of the rig with world units scaled to mm (translations times mm_per_unit).
Rig ScaleRigToMm(const Rig& rig, double mm_per_unit);

// Median distance from the camera centres to the focus point (rig units).
double MedianCameraDistance(const Rig& rig, Eigen::Vector3d* focus = nullptr);

// Errors: fewer than two cameras, degenerate axes (all parallel), an unknown
// scale that cannot be derived.
StatusOr<Stage> PlaceStage(const Rig& rig, const StageOptions& options);

}  // namespace arco::synth
