// Property tests for Rigid3d/Sim3d and the rotation helpers (Sophus style:
// random elements, group laws, round trips).
#include "arco/geometry/transform.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include "arco/geometry/rotation.h"

namespace arco {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Quaterniond RandomRotation(std::mt19937* rng) {
  std::normal_distribution<double> n(0, 1);
  Eigen::Quaterniond q(n(*rng), n(*rng), n(*rng), n(*rng));
  return q.normalized();
}

Eigen::Vector3d RandomVector(std::mt19937* rng, double scale = 1.0) {
  std::uniform_real_distribution<double> u(-scale, scale);
  return {u(*rng), u(*rng), u(*rng)};
}

Sim3d RandomSim(std::mt19937* rng) {
  std::uniform_real_distribution<double> s(0.2, 5.0);
  return Sim3d(s(*rng), RandomRotation(rng), RandomVector(rng, 3));
}

TEST(Rigid3d, GroupLawsHold) {
  std::mt19937 rng(11);
  for (int i = 0; i < 100; ++i) {
    const Rigid3d a(RandomRotation(&rng), RandomVector(&rng, 2));
    const Rigid3d b(RandomRotation(&rng), RandomVector(&rng, 2));
    const Rigid3d c(RandomRotation(&rng), RandomVector(&rng, 2));
    const Eigen::Vector3d p = RandomVector(&rng, 5);
    EXPECT_LT(((a * b) * p - a * (b * p)).norm(), 1e-12);
    EXPECT_LT((((a * b) * c) * p - (a * (b * c)) * p).norm(), 1e-12);
    EXPECT_LT(((a.Inverse() * a) * p - p).norm(), 1e-12);
    EXPECT_LT((a.Inverse() * (a * p) - p).norm(), 1e-12);
    EXPECT_LT((a.ToMatrix() * p.homogeneous() - a * p).norm(), 1e-12);
    EXPECT_NEAR((a * b).rotation.norm(), 1.0, 1e-15);
    const Rigid3d from_matrix(a.RotationMatrix(), a.translation);
    EXPECT_LT((from_matrix * p - a * p).norm(), 1e-12);
  }
}

TEST(RigidMatrix3d, IsTheSameMapAsRigid3dAndItsOperationsAreThePlainMatrixOnes) {
  std::mt19937 rng(13);
  for (int i = 0; i < 100; ++i) {
    const Rigid3d a(RandomRotation(&rng), RandomVector(&rng, 2));
    const Rigid3d b(RandomRotation(&rng), RandomVector(&rng, 2));
    const RigidMatrix3d ma(a), mb(b);
    const Eigen::Vector3d p = RandomVector(&rng, 5);
    EXPECT_LT((ma * p - a * p).norm(), 1e-12);
    EXPECT_LT(((ma * mb) * p - (a * b) * p).norm(), 1e-12);
    EXPECT_LT((ma.Inverse() * p - a.Inverse() * p).norm(), 1e-12);
    EXPECT_LT((ma.ToRigid3d() * p - a * p).norm(), 1e-12);
    // Bit for bit the expressions the hand-written R, t code used (its callers' outputs
    // stay byte-identical).
    const Eigen::Vector3d by_hand = ma.rotation * p + ma.translation;
    EXPECT_EQ(ma * p, by_hand);
    EXPECT_EQ((ma * mb).rotation, (ma.rotation * mb.rotation).eval());
    EXPECT_EQ((ma * mb).translation, (ma.rotation * mb.translation + ma.translation).eval());
    EXPECT_EQ(ma.Inverse().rotation, ma.rotation.transpose().eval());
    EXPECT_EQ(ma.Inverse().translation, (-(ma.rotation.transpose() * ma.translation)).eval());
  }
  EXPECT_THROW(RigidMatrix3d(Eigen::Matrix3d::Identity() * 2, Eigen::Vector3d::Zero()).ToRigid3d(),
               std::invalid_argument);
}

TEST(SimMatrix3d, IsTheSameMapAsSim3dAndItsOperationsAreThePlainMatrixOnes) {
  std::mt19937 rng(14);
  for (int i = 0; i < 100; ++i) {
    const Sim3d a = RandomSim(&rng);
    const SimMatrix3d ma(a);
    const Eigen::Vector3d p = RandomVector(&rng, 5);
    EXPECT_LT((ma * p - a * p).norm(), 1e-12);
    EXPECT_LT((ma.InverseMap(ma * p) - p).norm(), 1e-12);
    EXPECT_LT((ma.InverseMap(p) - a.Inverse() * p).norm(), 1e-12);
    EXPECT_LT((ma.ToSim3d() * p - a * p).norm(), 1e-12);
    EXPECT_EQ(ma.ToSim3d().scale, a.scale);
    // Bit for bit the expressions of the hand-written pose it replaces (InstrumentPose's
    // ToWorld and ToInstrument), so the instrument's outputs stay byte-identical.
    const Eigen::Vector3d to_world = ma.scale * (ma.rotation * p) + ma.translation;
    const Eigen::Vector3d to_local = ma.rotation.transpose() * (p - ma.translation) / ma.scale;
    EXPECT_EQ(ma * p, to_world);
    EXPECT_EQ(ma.InverseMap(p), to_local);
  }
  EXPECT_THROW(SimMatrix3d(0.0, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()).ToSim3d(),
               std::invalid_argument);
  EXPECT_THROW(SimMatrix3d(1.0, Eigen::Matrix3d::Identity() * 2, Eigen::Vector3d::Zero()).ToSim3d(),
               std::invalid_argument);
}

TEST(Sim3d, GroupLawsHoldAndScaleComposes) {
  std::mt19937 rng(12);
  for (int i = 0; i < 100; ++i) {
    const Sim3d a = RandomSim(&rng), b = RandomSim(&rng);
    const Eigen::Vector3d p = RandomVector(&rng, 5), q = RandomVector(&rng, 5);
    EXPECT_LT(((a * b) * p - a * (b * p)).norm(), 1e-10);
    EXPECT_LT((a.Inverse() * (a * p) - p).norm(), 1e-10);
    EXPECT_LT(((a * a.Inverse()) * p - p).norm(), 1e-10);
    EXPECT_NEAR((a * p - a * q).norm(), a.scale * (p - q).norm(), 1e-10);
    EXPECT_NEAR((a * b).scale, a.scale * b.scale, 1e-12);
    EXPECT_LT((a.ToMatrix() * p.homogeneous() - a * p).norm(), 1e-10);
  }
  const Rigid3d r(RandomRotation(&rng), RandomVector(&rng));
  const Eigen::Vector3d p(1, 2, 3);
  EXPECT_LT((Sim3d(r) * p - r * p).norm(), 1e-14);
}

TEST(Transforms, RejectInvalidArguments) {
  EXPECT_THROW(Rigid3d(Eigen::Matrix3d::Identity() * 2, Eigen::Vector3d::Zero()),
               std::invalid_argument);
  Eigen::Matrix3d mirror = Eigen::Matrix3d::Identity();
  mirror(2, 2) = -1;
  EXPECT_THROW(Rigid3d(mirror, Eigen::Vector3d::Zero()), std::invalid_argument);
  EXPECT_THROW(Sim3d(0.0, Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero()),
               std::invalid_argument);
  EXPECT_THROW(Sim3d(std::nan(""), Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero()),
               std::invalid_argument);
}

TEST(AxisAngle, RoundTripsIncludingNearZeroAndNearPi) {
  std::mt19937 rng(13);
  std::vector<Eigen::Vector3d> vectors = {Eigen::Vector3d::Zero(),
                                          Eigen::Vector3d(1e-12, 0, 0),
                                          Eigen::Vector3d(0, 3e-7, -1e-7),
                                          Eigen::Vector3d(0, 0, kPi - 1e-9),
                                          Eigen::Vector3d(kPi - 1e-6, 0, 0)};
  for (int i = 0; i < 200; ++i) {
    Eigen::Vector3d axis = RandomVector(&rng).normalized();
    vectors.push_back(axis * std::uniform_real_distribution<double>(0, kPi - 1e-3)(rng));
  }
  for (const Eigen::Vector3d& w : vectors) {
    const Eigen::Matrix3d r = RotationFromAxisAngle(w);
    EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-14);
    EXPECT_LT((AxisAngleFromRotation(r) - w).norm(), 1e-9 * std::max(1.0, w.norm()))
        << w.transpose();
    EXPECT_LT((AxisAngleFromQuaternion(QuaternionFromAxisAngle(w)) - w).norm(),
              1e-14 + 1e-12 * w.norm());
    EXPECT_LT(
        (r - Eigen::AngleAxisd(w.norm(), w.norm() > 0 ? w.normalized() : Eigen::Vector3d::UnitX())
                 .toRotationMatrix())
            .norm(),
        1e-14);
  }
  // Exactly pi: either sign of the axis is right.
  const Eigen::Vector3d half_turn =
      AxisAngleFromRotation(RotationFromAxisAngle(Eigen::Vector3d(0, kPi, 0)));
  EXPECT_NEAR(half_turn.norm(), kPi, 1e-12);
  EXPECT_NEAR(std::abs(half_turn.y()), kPi, 1e-12);
}

// d/dw (Exp(w) p) = -Exp(w) [p]x J_r(w), against central differences, from tiny angles
// (the series branch) to nearly pi.
TEST(RightJacobianSO3, GivesTheDerivativeOfARotatedPoint) {
  const Eigen::Vector3d p(30.0, -12.0, 55.0);
  for (const double angle : {0.0, 1e-6, 5e-5, 2e-4, 0.3, 1.7, 3.1}) {
    const Eigen::Vector3d w = angle * Eigen::Vector3d(0.48, -0.6, 0.64);
    const Eigen::Matrix3d analytic =
        -RotationFromAxisAngle(w) * CrossMatrix(p) * RightJacobianSO3(w);
    const double h = 1e-6;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d e = h * Eigen::Vector3d::Unit(k);
      const Eigen::Vector3d numeric =
          (RotationFromAxisAngle(w + e) * p - RotationFromAxisAngle(w - e) * p) / (2 * h);
      EXPECT_NEAR((analytic.col(k) - numeric).norm(), 0.0, 1e-6) << angle << " " << k;
    }
  }
  EXPECT_EQ(CrossMatrix(Eigen::Vector3d(1, 2, 3)) * Eigen::Vector3d(-4, 5, 0.5),
            Eigen::Vector3d(1, 2, 3).cross(Eigen::Vector3d(-4, 5, 0.5)));
}

TEST(RotationAngleBetween, MatchesTheAngleOfTheRelativeRotation) {
  const Eigen::Matrix3d a = RotationFromAxisAngle(Eigen::Vector3d(0.3, -0.2, 0.5));
  const Eigen::Matrix3d delta = RotationFromAxisAngle(Eigen::Vector3d(0, 0.25, 0));
  EXPECT_NEAR(RotationAngleBetween(a, a * delta), 0.25, 1e-12);
  EXPECT_NEAR(
      RotationAngleBetween(Eigen::Quaterniond(a), Eigen::Quaterniond(a * delta)), 0.25, 1e-12);
  // q and -q are the same rotation.
  Eigen::Quaterniond q(a), minus_q(a);
  minus_q.coeffs() = -minus_q.coeffs();
  EXPECT_NEAR(RotationAngleBetween(q, minus_q), 0.0, 1e-12);
}

TEST(NearestRotation, RecoversARotationFromANoisyMatrix) {
  std::mt19937 rng(14);
  const Eigen::Matrix3d r = RandomRotation(&rng).toRotationMatrix();
  Eigen::Matrix3d noisy = r;
  noisy += 1e-3 * Eigen::Matrix3d::Random();
  const Eigen::Matrix3d fixed = NearestRotation(noisy);
  EXPECT_LT((fixed.transpose() * fixed - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_NEAR(fixed.determinant(), 1.0, 1e-12);
  EXPECT_LT(RotationAngleBetween(fixed, r), 3e-3);
  EXPECT_LT((NearestRotation(r) - r).norm(), 1e-12);
}

TEST(KabschRotation, RecoversTheRotationOfVectorsAndNeverAReflection) {
  std::mt19937 rng(16);
  const Eigen::Matrix3d r = RandomRotation(&rng).toRotationMatrix();
  std::vector<Eigen::Vector3d> a, b;
  for (int i = 0; i < 6; ++i) {
    a.push_back(Eigen::Vector3d::Random());
    b.push_back(r * a.back());
  }
  EXPECT_LT((KabschRotation(a, b) - r).norm(), 1e-12);
  // Mirrored vectors (x -> -x): no rotation maps them, and the answer is still a proper
  // rotation (det +1), not the reflection the unconstrained solution would be.
  std::vector<Eigen::Vector3d> mirrored;
  for (const auto& p : a) mirrored.push_back(Eigen::Vector3d(-p.x(), p.y(), p.z()));
  const Eigen::Matrix3d m = KabschRotation(a, mirrored);
  EXPECT_NEAR(m.determinant(), 1.0, 1e-12);
  EXPECT_LT((m.transpose() * m - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  const std::vector<Eigen::Vector3d> plane = {{1, 0, 0}, {0, 1, 0}, {-1, -1, 0}};
  EXPECT_THROW(KabschRotation(a, plane), std::invalid_argument);
}

TEST(ProperRotationFromSvd, FlipsTheLastDirectionOnlyForAReflection) {
  std::mt19937 rng(17);
  const Eigen::Matrix3d u = RandomRotation(&rng).toRotationMatrix();
  const Eigen::Matrix3d v = RandomRotation(&rng).toRotationMatrix();
  bool reflected = true;
  EXPECT_LT((ProperRotationFromSvd(u, v, &reflected) - u * v.transpose()).norm(), 1e-12);
  EXPECT_FALSE(reflected);
  // A mirrored left factor (det -1): the last column is flipped back, det +1.
  Eigen::Matrix3d mirrored = u;
  mirrored.col(2) = -mirrored.col(2);
  const Eigen::Matrix3d r = ProperRotationFromSvd(mirrored, v, &reflected);
  EXPECT_TRUE(reflected);
  EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  EXPECT_LT((r - u * v.transpose()).norm(), 1e-12);
}

TEST(Rotation6d, RoundTripsAndOrthonormalisesAndRejectsDegenerate) {
  std::mt19937 rng(15);
  for (int i = 0; i < 50; ++i) {
    const Eigen::Matrix3d r = RandomRotation(&rng).toRotationMatrix();
    EXPECT_LT((*RotationFrom6d(RotationTo6d(r)) - r).norm(), 1e-12);
    // Scaled and skewed columns map back to the same rotation (Gram-Schmidt).
    Eigen::Matrix<double, 6, 1> v = RotationTo6d(r);
    v.head<3>() *= 3.0;
    v.tail<3>() = 0.5 * v.tail<3>() + 0.2 * v.head<3>();
    EXPECT_LT((*RotationFrom6d(v) - r).norm(), 1e-12);
  }
  Eigen::Matrix<double, 6, 1> parallel;
  parallel << 1, 0, 0, 2, 0, 0;
  EXPECT_FALSE(RotationFrom6d(parallel).has_value());
  EXPECT_FALSE(RotationFrom6d(Eigen::Matrix<double, 6, 1>::Zero()).has_value());
}

TEST(AverageQuaternions, IsOrderAndSignInvariantAndFindsTheMiddle) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, -1).normalized();
  const Eigen::Quaterniond base = QuaternionFromAxisAngle(Eigen::Vector3d(0.4, 0.1, -0.3));
  std::vector<Eigen::Quaterniond> qs;
  for (double angle : {-0.3, -0.1, 0.1, 0.3})
    qs.push_back(base * QuaternionFromAxisAngle(angle * axis));
  auto mean = AverageQuaternions(qs);
  ASSERT_TRUE(mean.has_value());
  EXPECT_LT(RotationAngleBetween(*mean, base), 1e-12);
  EXPECT_GE(mean->w(), 0);
  // Flip signs and reverse the order: identical result.
  std::vector<Eigen::Quaterniond> flipped(qs.rbegin(), qs.rend());
  flipped[1].coeffs() *= -1;
  flipped[2].coeffs() *= -1;
  auto mean2 = AverageQuaternions(flipped);
  EXPECT_LT((mean2->coeffs() - mean->coeffs()).norm(), 1e-12);
  // Weights pull the average toward the heavy rotation.
  auto weighted = AverageQuaternions({qs[0], qs[3]}, {3.0, 1.0});
  EXPECT_LT(RotationAngleBetween(*weighted, qs[0]), RotationAngleBetween(*weighted, qs[3]));
  auto single = AverageQuaternions({qs[2]}, {0.5});
  EXPECT_LT(RotationAngleBetween(*single, qs[2]), 1e-12);
  EXPECT_FALSE(AverageQuaternions({}).has_value());
  EXPECT_FALSE(AverageQuaternions({qs[0]}, {0.0}).has_value());
  EXPECT_THROW(AverageQuaternions({qs[0]}, {-1.0}), std::invalid_argument);
  EXPECT_THROW(AverageQuaternions({qs[0]}, {1.0, 2.0}), std::invalid_argument);
}

}  // namespace
}  // namespace arco
