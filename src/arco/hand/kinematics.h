// Forward kinematics of the hand model (conventions in hand_model.h).
// Templated on the scalar T so Ceres autodiff (ceres::Jet) gives Jacobians:
//   p_k = p_parent + G_parent * o_k,  G_k = G_parent * R_k(angles)
// with o_k the rest offset of keypoint k and R_k the joint rotation at k
// (identity for tips and for the rigid wrist->base bones).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>

#include "arco/hand/hand_model.h"

namespace arco::hand {

using HandPointsMm = std::array<Eigen::Vector3d, kNumHandKeypoints>;

// Rotation about unit `axis` by `angle` (Rodrigues' formula).
template <typename T>
Eigen::Matrix<T, 3, 3> AxisRotation(const Eigen::Vector3d& axis, const T& angle) {
  using std::cos;
  using std::sin;
  const T c = cos(angle), s = sin(angle), v = T(1) - c;
  const T x = T(axis.x()), y = T(axis.y()), z = T(axis.z());
  Eigen::Matrix<T, 3, 3> r;
  r << c + x * x * v, x * y * v - z * s, x * z * v + y * s,  //
      y * x * v + z * s, c + y * y * v, y * z * v - x * s,   //
      z * x * v - y * s, z * y * v + x * s, c + z * z * v;
  return r;
}

// Base-joint rotation R = R(a_abd, abd) * R(a_flex, flex) of one finger.
template <typename T>
Eigen::Matrix<T, 3, 3> BaseJointRotation(const HandModel& model, Finger finger, const T* dof4) {
  return AxisRotation<T>(model.axis(DofIndex(finger, FingerDof::kBaseAbd)), dof4[1]) *
         AxisRotation<T>(model.axis(DofIndex(finger, FingerDof::kBaseFlex)), dof4[0]);
}

// Keypoints base..tip of one finger in the wrist frame (mm), from its 4 dofs.
// out[j] is keypoint KeypointIndex(finger, j).
template <typename T>
void FingerPointsInWrist(const HandModel& model,
                         Finger finger,
                         const T* dof4,
                         Eigen::Matrix<T, 3, 1> out[4]) {
  const int k0 = KeypointIndex(finger, 0);
  out[0] = model.rest_offset_mm(k0).cast<T>();
  Eigen::Matrix<T, 3, 3> g = BaseJointRotation(model, finger, dof4);
  out[1] = out[0] + g * model.rest_offset_mm(k0 + 1).cast<T>();
  g = g * AxisRotation<T>(model.axis(DofIndex(finger, FingerDof::kMiddleFlex)), dof4[2]);
  out[2] = out[1] + g * model.rest_offset_mm(k0 + 2).cast<T>();
  g = g * AxisRotation<T>(model.axis(DofIndex(finger, FingerDof::kDistalFlex)), dof4[3]);
  out[3] = out[2] + g * model.rest_offset_mm(k0 + 3).cast<T>();
}

// All 21 keypoints in the wrist frame; angles has kNumJointDofs entries.
template <typename T>
void HandPointsInWrist(const HandModel& model, const T* angles, Eigen::Matrix<T, 3, 1> out[21]) {
  out[0].setZero();
  for (int f = 0; f < kNumFingers; ++f) {
    FingerPointsInWrist(model, static_cast<Finger>(f), angles + 4 * f, out + 1 + 4 * f);
  }
}

// Rotation matrix from an angle-axis vector, smooth at zero (for Jets too).
template <typename T>
Eigen::Matrix<T, 3, 3> AngleAxisToMatrix(const T* aa) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T theta2 = aa[0] * aa[0] + aa[1] * aa[1] + aa[2] * aa[2];
  Eigen::Matrix<T, 3, 3> k;
  k << T(0), -aa[2], aa[1], aa[2], T(0), -aa[0], -aa[1], aa[0], T(0);
  T a, b;  // R = I + a K + b K^2
  if (theta2 > T(1e-12)) {
    const T theta = sqrt(theta2);
    a = sin(theta) / theta;
    b = (T(1) - cos(theta)) / theta2;
  } else {  // Taylor expansion keeps derivatives exact at the identity
    a = T(1) - theta2 / T(6);
    b = T(0.5) - theta2 / T(24);
  }
  return Eigen::Matrix<T, 3, 3>::Identity() + a * k + b * k * k;
}

// All 21 keypoints in the world: wrist rotation as angle-axis (3), wrist
// position in world mm (3), joint angles (20).
template <typename T>
void HandPointsInWorld(const HandModel& model,
                       const T* wrist_aa,
                       const T* wrist_in_world_mm,
                       const T* angles,
                       Eigen::Matrix<T, 3, 1> out[21]) {
  HandPointsInWrist(model, angles, out);
  const Eigen::Matrix<T, 3, 3> r = AngleAxisToMatrix(wrist_aa);
  const Eigen::Matrix<T, 3, 1> t(wrist_in_world_mm[0], wrist_in_world_mm[1], wrist_in_world_mm[2]);
  for (int k = 0; k < kNumHandKeypoints; ++k) out[k] = r * out[k] + t;
}

// Keypoints in the world and their Jacobians with respect to the 26 parameters
// {wrist angle-axis (3), wrist position (3), angles (20)}, exploiting the tree:
// a finger's points depend only on the wrist and its own 4 dofs, so each
// finger runs in ceres::Jet<double, 4> and the wrist rotation in Jet<3>.
// Matches HandPointsInWorld<Jet<double, 26>> (tested) at a fraction of the cost.
using HandPointJacobian = Eigen::Matrix<double, 3, 6 + kNumJointDofs>;
void HandPointsAndJacobians(const HandModel& model,
                            const double* wrist_aa,
                            const double* wrist_in_world_mm,
                            const double* angles,
                            Eigen::Vector3d points[kNumHandKeypoints],
                            HandPointJacobian jacobians[kNumHandKeypoints]);

// Convenience (double): keypoints of `pose` in the world / in the wrist frame.
HandPointsMm ForwardKinematics(const HandModel& model, const HandPose& pose);
HandPointsMm ForwardKinematicsInWrist(const HandModel& model, const HandPose& pose);
Eigen::Vector3d FingertipInWorld(const HandModel& model, const HandPose& pose, Finger finger);

// Local joint rotation R_k at each joint keypoint (identity elsewhere), in the
// parent's frame: what fusion averages over views.
std::array<Eigen::Matrix3d, kNumHandKeypoints> LocalJointRotations(const HandModel& model,
                                                                   const HandPose& pose);

}  // namespace arco::hand
