// Rotation helpers. A rotation vector (axis-angle) w has angle |w| in radians
// about the axis w/|w|. Quaternions follow Eigen (Hamilton, w x y z).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <vector>

namespace arco {

// Rodrigues' formula, R = I + sin(a) K + (1 - cos(a)) K^2; accurate near a = 0.
Eigen::Matrix3d RotationFromAxisAngle(const Eigen::Vector3d& rotation_vector);
// Inverse of the above with angle in [0, pi]; accurate near 0 and near pi.
Eigen::Vector3d AxisAngleFromRotation(const Eigen::Matrix3d& rotation);
// The right Jacobian of SO(3), J_r(w) = I - (1 - cos a)/a^2 [w]x + (a - sin a)/a^3 [w]x^2
// (a = |w|; Sola, Deray & Atchuthan 2018, "A micro Lie theory", eq. 143): for small d,
// Exp(w + d) = Exp(w) Exp(J_r(w) d), so d/dw (Exp(w) p) = -Exp(w) [p]x J_r(w). Series
// coefficients near a = 0.
Eigen::Matrix3d RightJacobianSO3(const Eigen::Vector3d& rotation_vector);
// [v]x, the cross-product matrix: [v]x p = v x p.
Eigen::Matrix3d CrossMatrix(const Eigen::Vector3d& v);

Eigen::Quaterniond QuaternionFromAxisAngle(const Eigen::Vector3d& rotation_vector);
// Angle in [0, pi] (q and -q give the same vector).
Eigen::Vector3d AxisAngleFromQuaternion(const Eigen::Quaterniond& rotation);

// Angle of a^T b in radians, in [0, pi].
double RotationAngleBetween(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b);
double RotationAngleBetween(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b);

// The rotation nearest to `matrix` in the Frobenius norm (SVD, det fixed to +1).
Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& matrix);
// The proper rotation left * diag(1, 1, +-1) * right^T from the orthogonal factors of an
// SVD, the sign making det = +1; `reflected`, when given, is set when it is -1. The one
// place arco turns a cross-covariance into a rotation: NearestRotation (U, V of the
// matrix), KabschRotation (V, U of sum a b^T; Kabsch 1976) and the Umeyama alignment
// (geometry/alignment.h, which also needs the singular values; Umeyama, PAMI 1991).
Eigen::Matrix3d ProperRotationFromSvd(const Eigen::Matrix3d& left,
                                      const Eigen::Matrix3d& right,
                                      bool* reflected = nullptr);

// The rotation R minimising sum_i |R a_i - b_i|^2 over vectors already relative to a
// common origin (Kabsch 1976: SVD of sum a_i b_i^T, det fixed to +1). Sizes must match.
Eigen::Matrix3d KabschRotation(const std::vector<Eigen::Vector3d>& a,
                               const std::vector<Eigen::Vector3d>& b);

// The 6D rotation representation (Zhou et al., CVPR 2019): the first two columns
// of R, mapped back by Gram-Schmidt. Nullopt when the columns are (nearly) parallel
// or zero.
std::optional<Eigen::Matrix3d> RotationFrom6d(const Eigen::Matrix<double, 6, 1>& columns);
Eigen::Matrix<double, 6, 1> RotationTo6d(const Eigen::Matrix3d& rotation);

// Weighted quaternion average by the eigenvector method (Markley, Cheng, Crassidis
// & Oshman 2007): the unit eigenvector of M = sum_i w_i q_i q_i^T with the largest
// eigenvalue. Independent of order and of each q_i's sign. Returned with w >= 0.
// Nullopt when there are no quaternions or the weights sum to <= 0. Throws
// std::invalid_argument on mismatched sizes or negative/non-finite weights
// (empty `weights` means all 1).
std::optional<Eigen::Quaterniond> AverageQuaternions(
    const std::vector<Eigen::Quaterniond>& rotations, const std::vector<double>& weights = {});

}  // namespace arco
