#include "arco/hand/kinematics.h"

#include <ceres/jet.h>

namespace arco::hand {

void HandPointsAndJacobians(const HandModel& model,
                            const double* wrist_aa,
                            const double* wrist_in_world_mm,
                            const double* angles,
                            Eigen::Vector3d points[kNumHandKeypoints],
                            HandPointJacobian jacobians[kNumHandKeypoints]) {
  using Jet3 = ceres::Jet<double, 3>;
  using Jet4 = ceres::Jet<double, 4>;
  const Jet3 aa[3] = {Jet3(wrist_aa[0], 0), Jet3(wrist_aa[1], 1), Jet3(wrist_aa[2], 2)};
  const Eigen::Matrix<Jet3, 3, 3> rj = AngleAxisToMatrix(aa);
  Eigen::Matrix3d r;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r(i, j) = rj(i, j).a;
  }
  const Eigen::Vector3d t(wrist_in_world_mm[0], wrist_in_world_mm[1], wrist_in_world_mm[2]);
  points[0] = t;
  jacobians[0].setZero();
  jacobians[0].block<3, 3>(0, 3).setIdentity();
  for (int f = 0; f < kNumFingers; ++f) {
    Jet4 dof[4];
    for (int i = 0; i < 4; ++i) dof[i] = Jet4(angles[4 * f + i], i);
    Eigen::Matrix<Jet4, 3, 1> local[4];
    FingerPointsInWrist(model, static_cast<Finger>(f), dof, local);
    for (int j = 0; j < 4; ++j) {
      const int k = 1 + 4 * f + j;
      Eigen::Vector3d pl;
      Eigen::Matrix<double, 3, 4> dpl;
      for (int c = 0; c < 3; ++c) pl[c] = local[j][c].a, dpl.row(c) = local[j][c].v.transpose();
      points[k] = r * pl + t;
      HandPointJacobian& jac = jacobians[k];
      jac.setZero();
      for (int row = 0; row < 3; ++row) {  // d(R pl)/d aa = sum_c dR(row, c)/d aa * pl[c]
        jac.block<1, 3>(row, 0) =
            (rj(row, 0).v * pl[0] + rj(row, 1).v * pl[1] + rj(row, 2).v * pl[2]).transpose();
      }
      jac.block<3, 3>(0, 3).setIdentity();
      jac.block<3, 4>(0, 6 + 4 * f) = r * dpl;
    }
  }
}

HandPointsMm ForwardKinematicsInWrist(const HandModel& model, const HandPose& pose) {
  Eigen::Vector3d points[kNumHandKeypoints];
  HandPointsInWrist(model, pose.angles_rad.data(), points);
  HandPointsMm out;
  for (int k = 0; k < kNumHandKeypoints; ++k) out[k] = points[k];
  return out;
}

HandPointsMm ForwardKinematics(const HandModel& model, const HandPose& pose) {
  HandPointsMm out = ForwardKinematicsInWrist(model, pose);
  for (auto& p : out) p = pose.world_from_wrist * p;
  return out;
}

Eigen::Vector3d FingertipInWorld(const HandModel& model, const HandPose& pose, Finger finger) {
  Eigen::Vector3d points[4];
  FingerPointsInWrist(model, finger, pose.angles_rad.data() + 4 * static_cast<int>(finger), points);
  return pose.world_from_wrist * points[3];
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
