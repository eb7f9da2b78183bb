#include "arco/hand/kinematics.h"

namespace arco::hand {

HandPointsMm ForwardKinematicsInWrist(const HandModel& model, const HandPose& pose) {
  Eigen::Vector3d points[kNumHandKeypoints];
  HandPointsInWrist(model, pose.angles_rad.data(), points);
  HandPointsMm out;
  for (int k = 0; k < kNumHandKeypoints; ++k) out[k] = points[k];
  return out;
}

HandPointsMm ForwardKinematics(const HandModel& model, const HandPose& pose) {
  HandPointsMm out = ForwardKinematicsInWrist(model, pose);
  for (auto& p : out) p = pose.world_from_wrist_rotation * p + pose.wrist_in_world_mm;
  return out;
}

Eigen::Vector3d FingertipInWorld(const HandModel& model, const HandPose& pose, Finger finger) {
  Eigen::Vector3d points[4];
  FingerPointsInWrist(model, finger, pose.angles_rad.data() + 4 * static_cast<int>(finger), points);
  return pose.world_from_wrist_rotation * points[3] + pose.wrist_in_world_mm;
}

std::array<Eigen::Matrix3d, kNumHandKeypoints> LocalJointRotations(const HandModel& model,
                                                                   const HandPose& pose) {
  std::array<Eigen::Matrix3d, kNumHandKeypoints> out;
  for (auto& r : out) r.setIdentity();
  for (int f = 0; f < kNumFingers; ++f) {
    const Finger finger = static_cast<Finger>(f);
    const double* dof = pose.angles_rad.data() + 4 * f;
    const int k0 = KeypointIndex(finger, 0);
    out[k0] = BaseJointRotation(model, finger, dof);
    out[k0 + 1] = AxisRotation(model.axis(DofIndex(finger, FingerDof::kMiddleFlex)), dof[2]);
    out[k0 + 2] = AxisRotation(model.axis(DofIndex(finger, FingerDof::kDistalFlex)), dof[3]);
  }
  return out;
}

}  // namespace arco::hand
