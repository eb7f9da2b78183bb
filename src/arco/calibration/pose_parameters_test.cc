#include "arco/calibration/pose_parameters.h"

#include <gtest/gtest.h>

#include <cmath>

#include "arco/geometry/rotation.h"

namespace arco::calibration {
namespace {

TEST(PoseParameters, RoundTripKeepsThePose) {
  const Eigen::Matrix3d R = RotationFromAxisAngle(Eigen::Vector3d(0.3, -1.2, 2.0));
  const Eigen::Vector3d t(1.5, -2.5, 40.0);
  double params[kPoseParams];
  PoseToParams(R, t, params);
  EXPECT_NEAR(params[0], 0.3, 1e-12);
  EXPECT_NEAR(params[1], -1.2, 1e-12);
  EXPECT_NEAR(params[2], 2.0, 1e-12);
  Eigen::Matrix3d R2;
  Eigen::Vector3d t2;
  ParamsToPose(params, &R2, &t2);
  EXPECT_LT((R2 - R).norm(), 1e-12);
  EXPECT_EQ(t2, t);
}

TEST(PoseParameters, ARigidPoseGivesTheSameParametersAsItsRotationAndTranslation) {
  const RigidMatrix3d pose(RotationFromAxisAngle(Eigen::Vector3d(-0.4, 0.9, 0.1)),
                           Eigen::Vector3d(10, 20, -30));
  double params[kPoseParams];
  PoseToParams(pose.rotation, pose.translation, params);
  const std::array<double, kPoseParams> from_rigid = ParamsFromRigid(pose);
  for (int i = 0; i < kPoseParams; ++i) EXPECT_EQ(from_rigid[i], params[i]);
  const RigidMatrix3d back = RigidFromParams(from_rigid.data());
  EXPECT_LT((back.rotation - pose.rotation).norm(), 1e-12);
  EXPECT_EQ(back.translation, pose.translation);
}

TEST(Rms, OfNoneIsZeroAndOfValuesTheirQuadraticMean) {
  EXPECT_EQ(Rms({}), 0);
  EXPECT_DOUBLE_EQ(Rms({3, -4}), std::sqrt(12.5));
}

}  // namespace
}  // namespace arco::calibration
