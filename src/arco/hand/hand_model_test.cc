#include "arco/hand/hand_model.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "arco/hand/hand_test_util.h"
#include "arco/hand/kinematics.h"

namespace arco::hand {
namespace {

constexpr double kDeg = M_PI / 180.0;

TEST(HandModel, RestPoseReproducesRestPoints) {
  for (HandSide side : {HandSide::kLeft, HandSide::kRight}) {
    const HandModel model = HandModel::Default(side);
    const HandPointsMm points = ForwardKinematics(model, HandPose{});
    const RestPointsMm rest = DefaultRightRestPointsMm();
    const double mirror = side == HandSide::kLeft ? -1 : 1;
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      EXPECT_NEAR(points[k].x(), mirror * rest[k].x(), 1e-9) << KeypointName(k);
      EXPECT_NEAR(points[k].y(), rest[k].y(), 1e-9);
      EXPECT_NEAR(points[k].z(), rest[k].z(), 1e-9);
      EXPECT_TRUE(points[k].isApprox(model.rest_point_mm(k), 1e-12) || k == 0);
    }
  }
}

TEST(HandModel, DefaultLengthsFollowDomainTable) {
  const HandModel model = HandModel::Default(HandSide::kRight);
  EXPECT_NEAR(model.bone_length_mm(KeypointIndex(Finger::kIndex, 0)), 88, 1e-9);
  EXPECT_NEAR(model.bone_length_mm(KeypointIndex(Finger::kMiddle, 1)), 45, 1e-9);
  EXPECT_NEAR(model.bone_length_mm(KeypointIndex(Finger::kLittle, 2)), 20, 1e-9);
  EXPECT_NEAR(model.bone_length_mm(TipKeypoint(Finger::kRing)), 22, 1e-9);
}

TEST(HandModel, TopologyFollowsCocoWholeBodyOrder) {
  EXPECT_EQ(ParentKeypoint(0), -1);
  for (int f = 0; f < kNumFingers; ++f) {
    EXPECT_EQ(ParentKeypoint(KeypointIndex(static_cast<Finger>(f), 0)), 0);
    for (int j = 1; j < 4; ++j) {
      const int k = KeypointIndex(static_cast<Finger>(f), j);
      EXPECT_EQ(ParentKeypoint(k), k - 1);
    }
  }
  EXPECT_STREQ(KeypointName(8), "index_tip");
  EXPECT_STREQ(KeypointName(17), "little_mcp");
  EXPECT_STREQ(DofName(DofIndex(Finger::kThumb, FingerDof::kDistalFlex)), "thumb_ip_flex");
}

TEST(HandModel, AxesAreUnitAndFlexionAxesPerpendicularToTheirBone) {
  for (HandSide side : {HandSide::kLeft, HandSide::kRight}) {
    const HandModel model = HandModel::Default(side);
    for (int d = 0; d < kNumJointDofs; ++d) EXPECT_NEAR(model.axis(d).norm(), 1.0, 1e-12);
    for (int f = 0; f < kNumFingers; ++f) {
      const Finger finger = static_cast<Finger>(f);
      const int k0 = KeypointIndex(finger, 0);
      const int flex_slots[3] = {0, 2, 3};
      for (int j = 0; j < 3; ++j) {
        const Eigen::Vector3d bone = model.rest_offset_mm(k0 + j + 1).normalized();
        EXPECT_NEAR(model.axis(4 * f + flex_slots[j]).dot(bone), 0.0, 1e-12);
      }
      EXPECT_NEAR(model.axis(DofIndex(finger, FingerDof::kBaseFlex))
                      .dot(model.axis(DofIndex(finger, FingerDof::kBaseAbd))),
                  0.0,
                  1e-12);
    }
  }
}

TEST(HandModel, FlexionCurlsTowardsPalmAndAbductionTowardsThumbInBothHands) {
  for (HandSide side : {HandSide::kLeft, HandSide::kRight}) {
    const HandModel model = HandModel::Default(side);
    const double radial = side == HandSide::kRight ? 1.0 : -1.0;
    for (Finger finger : {Finger::kIndex, Finger::kMiddle, Finger::kRing, Finger::kLittle}) {
      const Eigen::Vector3d rest_tip = FingertipInWorld(model, HandPose{}, finger);
      for (FingerDof dof : {FingerDof::kBaseFlex, FingerDof::kMiddleFlex, FingerDof::kDistalFlex}) {
        HandPose pose;
        pose.angle_rad(finger, dof) = 30 * kDeg;
        EXPECT_GT(FingertipInWorld(model, pose, finger).z(), rest_tip.z() + 5)
            << FingerName(finger);
      }
      HandPose pose;
      pose.angle_rad(finger, FingerDof::kBaseAbd) = 15 * kDeg;
      EXPECT_GT(radial * (FingertipInWorld(model, pose, finger).x() - rest_tip.x()), 5.0);
    }
    // Thumb flexion at MCP/IP moves the tip towards the palm and the little finger.
    const Eigen::Vector3d rest_thumb = FingertipInWorld(model, HandPose{}, Finger::kThumb);
    HandPose pose;
    pose.angle_rad(Finger::kThumb, FingerDof::kMiddleFlex) = 40 * kDeg;
    const Eigen::Vector3d bent = FingertipInWorld(model, pose, Finger::kThumb);
    EXPECT_GT(bent.z(), rest_thumb.z() + 5);
    EXPECT_LT(radial * bent.x(), radial * rest_thumb.x());
  }
}

TEST(HandModel, LeftHandIsMirrorOfRightForSameAngles) {
  const HandModel right = HandModel::Default(HandSide::kRight);
  const HandModel left = right.Mirrored();
  EXPECT_EQ(left.side(), HandSide::kLeft);
  std::mt19937 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    HandPose pose = testing::RandomPose(right, rng);
    const HandPointsMm r = ForwardKinematicsInWrist(right, pose);
    const HandPointsMm l = ForwardKinematicsInWrist(left, pose);
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      EXPECT_NEAR(l[k].x(), -r[k].x(), 1e-9);
      EXPECT_NEAR(l[k].y(), r[k].y(), 1e-9);
      EXPECT_NEAR(l[k].z(), r[k].z(), 1e-9);
    }
  }
}

TEST(HandModel, BonesAreRigidUnderAnyPose) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::mt19937 rng(11);
  for (int trial = 0; trial < 50; ++trial) {
    const HandPose pose = testing::RandomPose(model, rng);
    const HandPointsMm p = ForwardKinematics(model, pose);
    for (int k = 1; k < kNumHandKeypoints; ++k) {
      EXPECT_NEAR((p[k] - p[ParentKeypoint(k)]).norm(), model.bone_length_mm(k), 1e-9);
    }
  }
}

TEST(HandModel, WithBoneLengthsSetsExactLengthsAndKeepsDirections) {
  const HandModel base = HandModel::Default(HandSide::kRight);
  BoneLengthsMm lengths = base.bone_lengths_mm();
  for (int k = 1; k < kNumHandKeypoints; ++k) lengths[k] *= 1.0 + 0.01 * k;
  StatusOr<HandModel> model = base.WithBoneLengths(lengths);
  ASSERT_TRUE(model.ok()) << model.status().message();
  for (int k = 1; k < kNumHandKeypoints; ++k) {
    EXPECT_NEAR(model->bone_length_mm(k), lengths[k], 1e-9);
    EXPECT_NEAR(
        model->rest_offset_mm(k).normalized().dot(base.rest_offset_mm(k).normalized()), 1.0, 1e-12);
  }
  lengths[7] = std::nan("");
  EXPECT_FALSE(base.WithBoneLengths(lengths).ok());
  lengths[7] = 0.2;
  EXPECT_FALSE(base.WithBoneLengths(lengths).ok());
}

TEST(HandModel, CreateRejectsBadInput) {
  RestPointsMm points = DefaultRightRestPointsMm();
  JointLimitsDeg limits = DefaultJointLimitsDeg();
  points[3].x() = std::nan("");
  EXPECT_FALSE(HandModel::Create(HandSide::kRight, points, limits).ok());
  points = DefaultRightRestPointsMm();
  points[6] = points[5];
  const StatusOr<HandModel> degenerate = HandModel::Create(HandSide::kRight, points, limits);
  ASSERT_FALSE(degenerate.ok());
  EXPECT_NE(degenerate.status().message().find("index_pip"), std::string::npos);
  limits[4] = {10, -10};
  EXPECT_FALSE(HandModel::Create(HandSide::kRight, DefaultRightRestPointsMm(), limits).ok());
}

TEST(HandModel, LimitsTableMatchesDomainDefaults) {
  const JointLimitsDeg l = DefaultJointLimitsDeg();
  EXPECT_EQ(l[DofIndex(Finger::kIndex, FingerDof::kBaseFlex)].max_deg, 90);
  EXPECT_EQ(l[DofIndex(Finger::kIndex, FingerDof::kBaseFlex)].min_deg, -30);
  EXPECT_EQ(l[DofIndex(Finger::kRing, FingerDof::kBaseAbd)].max_deg, 20);
  EXPECT_EQ(l[DofIndex(Finger::kMiddle, FingerDof::kMiddleFlex)].max_deg, 110);
  EXPECT_EQ(l[DofIndex(Finger::kLittle, FingerDof::kDistalFlex)].max_deg, 90);
  EXPECT_EQ(l[DofIndex(Finger::kThumb, FingerDof::kDistalFlex)].min_deg, -15);
  EXPECT_EQ(l[DofIndex(Finger::kThumb, FingerDof::kMiddleFlex)].max_deg, 55);
  const HandModel model = HandModel::Default(HandSide::kRight);
  EXPECT_NEAR(model.max_rad(DofIndex(Finger::kIndex, FingerDof::kMiddleFlex)), 110 * kDeg, 1e-15);
}

TEST(HandModel, CountAndClampLimitViolations) {
  const HandModel model = HandModel::Default(HandSide::kRight);
  HandPose pose;
  EXPECT_EQ(CountLimitViolations(model, pose), 0);
  pose.angle_rad(Finger::kIndex, FingerDof::kMiddleFlex) = -0.3;  // PIP beyond -10 degrees
  pose.angle_rad(Finger::kRing, FingerDof::kBaseAbd) = 1.0;
  pose.angle_rad(Finger::kThumb, FingerDof::kBaseFlex) = std::nan("");
  EXPECT_EQ(CountLimitViolations(model, pose), 3);
  const HandPose clamped = ClampToLimits(model, pose);
  EXPECT_EQ(CountLimitViolations(model, clamped), 0);
  EXPECT_NEAR(clamped.angle_rad(Finger::kIndex, FingerDof::kMiddleFlex), -10 * kDeg, 1e-15);
  EXPECT_NEAR(clamped.angle_rad(Finger::kRing, FingerDof::kBaseAbd), 20 * kDeg, 1e-15);
  EXPECT_EQ(clamped.angle_rad(Finger::kThumb, FingerDof::kBaseFlex), 0.0);
}

TEST(HandPose, WristAngleAxisRoundTrip) {
  std::mt19937 rng(3);
  const HandModel model = HandModel::Default(HandSide::kRight);
  for (int trial = 0; trial < 20; ++trial) {
    HandPose pose = testing::RandomPose(model, rng);
    const Eigen::Matrix3d r = pose.world_from_wrist.rotation;
    pose.SetWristAngleAxis(pose.WristAngleAxis());
    EXPECT_TRUE(pose.world_from_wrist.rotation.isApprox(r, 1e-12));
  }
  HandPose identity;
  identity.SetWristAngleAxis(Eigen::Vector3d::Zero());
  EXPECT_TRUE(identity.world_from_wrist.rotation.isIdentity());
}

// Autodiff Jacobian of HandPointsInWorld (26 parameters -> 63 outputs) against
// central differences, including a wrist rotation near the identity.
TEST(HandKinematics, AutodiffJacobianMatchesCentralDifferences) {
  using Jet = ceres::Jet<double, 26>;
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::mt19937 rng(5);
  for (int trial = 0; trial < 6; ++trial) {
    HandPose pose = testing::RandomPose(model, rng, 0.05);
    if (trial == 0) pose.SetWristAngleAxis(Eigen::Vector3d(1e-9, -2e-9, 0));
    double x[26];
    const Eigen::Vector3d aa = pose.WristAngleAxis();
    for (int i = 0; i < 3; ++i) x[i] = aa[i], x[3 + i] = pose.world_from_wrist.translation[i];
    for (int d = 0; d < kNumJointDofs; ++d) x[6 + d] = pose.angles_rad[d];
    Jet jx[26];
    for (int i = 0; i < 26; ++i) jx[i] = Jet(x[i], i);
    Eigen::Matrix<Jet, 3, 1> jp[21];
    HandPointsInWorld(model, jx, jx + 3, jx + 6, jp);
    auto eval = [&](const double* params, int k) {
      Eigen::Vector3d p[21];
      HandPointsInWorld(model, params, params + 3, params + 6, p);
      return p[k];
    };
    const double h = 1e-6;
    for (int i = 0; i < 26; ++i) {
      double xp[26], xm[26];
      std::copy(x, x + 26, xp);
      std::copy(x, x + 26, xm);
      xp[i] += h;
      xm[i] -= h;
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        const Eigen::Vector3d numeric = (eval(xp, k) - eval(xm, k)) / (2 * h);
        for (int r = 0; r < 3; ++r) {
          EXPECT_NEAR(jp[k][r].v[i], numeric[r], 1e-5 * (1 + std::abs(numeric[r])))
              << "param " << i << " keypoint " << k;
          EXPECT_NEAR(jp[k][r].a, eval(x, k)[r], 1e-9);
        }
      }
    }
  }
}

}  // namespace
}  // namespace arco::hand

namespace arco::hand {
namespace {

// Tree-structured analytic-chain Jacobians against full 26-wide autodiff.
TEST(HandKinematics, FastJacobiansMatchFullAutodiff) {
  using Jet = ceres::Jet<double, 26>;
  const HandModel model = HandModel::Default(HandSide::kRight);
  std::mt19937 rng(15);
  for (int trial = 0; trial < 10; ++trial) {
    HandPose pose = testing::RandomPose(model, rng);
    if (trial == 0) pose.SetWristAngleAxis(Eigen::Vector3d::Zero());
    double x[26];
    const Eigen::Vector3d aa = pose.WristAngleAxis();
    for (int i = 0; i < 3; ++i) x[i] = aa[i], x[3 + i] = pose.world_from_wrist.translation[i];
    for (int d = 0; d < kNumJointDofs; ++d) x[6 + d] = pose.angles_rad[d];
    Jet jx[26];
    for (int i = 0; i < 26; ++i) jx[i] = Jet(x[i], i);
    Eigen::Matrix<Jet, 3, 1> jp[21];
    HandPointsInWorld(model, jx, jx + 3, jx + 6, jp);
    Eigen::Vector3d points[21];
    HandPointJacobian jac[21];
    HandPointsAndJacobians(model, x, x + 3, x + 6, points, jac);
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      for (int r = 0; r < 3; ++r) {
        EXPECT_NEAR(points[k][r], jp[k][r].a, 1e-10);
        for (int i = 0; i < 26; ++i)
          EXPECT_NEAR(jac[k](r, i), jp[k][r].v[i], 1e-10) << k << " " << i;
      }
    }
  }
}

}  // namespace
}  // namespace arco::hand
