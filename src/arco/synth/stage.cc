#include "arco/synth/stage.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

#include "arco/util/stats.h"

namespace arco::synth {

// Measured on ../shared/data/spd/cello_1113_scale_camera.xml scaled by 695 mm /
// its nut-bridge distance in Metashape units (see stage_test.cc).
const double kSpdCameraDistanceMm = 1999.0;

Status StageOptions::Validate() const {
  if (!(mm_per_unit >= 0) || !std::isfinite(mm_per_unit)) {
    return Status::Error("mm_per_unit must be >= 0 (0 = automatic)");
  }
  if (!(camera_distance_mm >= 0) || !std::isfinite(camera_distance_mm)) {
    return Status::Error("camera_distance_mm must be >= 0 (0 = the SPD rig's)");
  }
  if (!focus_in_performer_mm.allFinite()) return Status::Error("focus point must be finite");
  return Status::Ok();
}

Rig ScaleRigToMm(const Rig& rig, double mm_per_unit) {
  Rig out = rig;
  for (Camera& c : out.cameras) c.cam_from_world.translation *= mm_per_unit;
  out.units = "mm";
  return out;
}

double MedianCameraDistance(const Rig& rig, Eigen::Vector3d* focus_out) {
  // Least-squares point nearest to every optical axis: sum (I - d d^T) (x - c) = 0.
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const Camera& cam : rig.cameras) {
    const Eigen::Vector3d c = cam.CenterInWorld();
    const Eigen::Vector3d d = cam.cam_from_world.rotation.row(2).transpose().normalized();
    const Eigen::Matrix3d p = Eigen::Matrix3d::Identity() - d * d.transpose();
    a += p;
    b += p * c;
  }
  const Eigen::Vector3d focus = a.ldlt().solve(b);
  if (focus_out) *focus_out = focus;
  std::vector<double> dist;
  for (const Camera& cam : rig.cameras) dist.push_back((cam.CenterInWorld() - focus).norm());
  if (dist.empty()) return 0;
  return UpperMedianInPlace(dist.begin(), dist.end());
}

StatusOr<Stage> PlaceStage(const Rig& rig, const StageOptions& options) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  if (rig.cameras.size() < 2) {
    return Status::Error("the calibration has " + std::to_string(rig.cameras.size()) +
                         " camera(s); a capture needs at least 2");
  }
  // Optical axes must not all be parallel, or there is no focus.
  Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
  for (const Camera& cam : rig.cameras) {
    const Eigen::Vector3d d = cam.cam_from_world.rotation.row(2).transpose().normalized();
    spread += Eigen::Matrix3d::Identity() - d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(spread);
  if (!(eig.eigenvalues()(0) > 1e-6 * rig.cameras.size())) {
    return Status::Error("the cameras' optical axes are parallel: no common focus");
  }
  Stage stage;
  Eigen::Vector3d focus_units;
  const double median_units = MedianCameraDistance(rig, &focus_units);
  double mm_per_unit = options.mm_per_unit;
  if (mm_per_unit == 0) {
    if (rig.units == "mm") {
      mm_per_unit = 1;
    } else if (rig.units == "m") {
      mm_per_unit = 1000;
    } else {
      const double target =
          options.camera_distance_mm > 0 ? options.camera_distance_mm : kSpdCameraDistanceMm;
      if (!(median_units > 0)) return Status::Error("cameras coincide: cannot derive a scale");
      mm_per_unit = target / median_units;
    }
  }
  stage.mm_per_unit = mm_per_unit;
  stage.focus_in_world_mm = focus_units * mm_per_unit;
  stage.median_camera_distance_mm = median_units * mm_per_unit;

  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  for (const Camera& cam : rig.cameras) up -= cam.cam_from_world.rotation.row(1).transpose();
  if (!(up.norm() > 1e-6)) return Status::Error("cannot tell up from the cameras");
  up.normalize();
  Eigen::Vector3d forward = Eigen::Vector3d::Zero();
  for (const Camera& cam : rig.cameras) {
    Eigen::Vector3d d = cam.CenterInWorld() * mm_per_unit - stage.focus_in_world_mm;
    d -= d.dot(up) * up;
    if (d.norm() > 1e-9) forward += d.normalized();
  }
  if (forward.norm() < 1e-3) {  // cameras all around: face the first camera
    forward = rig.cameras[0].CenterInWorld() * mm_per_unit - stage.focus_in_world_mm;
    forward -= forward.dot(up) * up;
  }
  if (!(forward.norm() > 1e-9)) return Status::Error("cannot tell the performer's front");
  forward.normalize();
  const Eigen::Vector3d left = up.cross(forward);  // x = y cross z
  Eigen::Matrix3d& rotation = stage.world_from_performer.rotation;
  rotation.col(0) = left;
  rotation.col(1) = up;
  rotation.col(2) = forward;
  stage.world_from_performer.translation =
      stage.focus_in_world_mm - rotation * options.focus_in_performer_mm;
  return stage;
}

}  // namespace arco::synth
