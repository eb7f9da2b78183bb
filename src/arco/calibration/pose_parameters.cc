#include "arco/calibration/pose_parameters.h"

#include <cmath>

#include "arco/geometry/rotation.h"

namespace arco::calibration {

void PoseToParams(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, double* params) {
  const Eigen::Vector3d aa = AxisAngleFromRotation(R);
  for (int i = 0; i < 3; ++i) params[i] = aa[i], params[3 + i] = t[i];
}

void ParamsToPose(const double* params, Eigen::Matrix3d* R, Eigen::Vector3d* t) {
  *R = RotationFromAxisAngle(Eigen::Vector3d(params[0], params[1], params[2]));
  *t = Eigen::Vector3d(params[3], params[4], params[5]);
}

std::array<double, kPoseParams> ParamsFromRigid(const RigidMatrix3d& pose) {
  std::array<double, kPoseParams> params;
  PoseToParams(pose.rotation, pose.translation, params.data());
  return params;
}

RigidMatrix3d RigidFromParams(const double* params) {
  RigidMatrix3d pose;
  ParamsToPose(params, &pose.rotation, &pose.translation);
  return pose;
}

double Rms(const std::vector<double>& values) {
  if (values.empty()) return 0;
  double sum = 0;
  for (double v : values) sum += v * v;
  return std::sqrt(sum / values.size());
}

}  // namespace arco::calibration
