#include "arco/geometry/rotation.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>
#include <stdexcept>

namespace arco {

Eigen::Quaterniond QuaternionFromAxisAngle(const Eigen::Vector3d& rotation_vector) {
  const double angle = rotation_vector.norm();
  const double half = 0.5 * angle;
  // sin(a/2)/a by its Taylor series near 0 keeps full precision for tiny angles.
  const double k = angle < 1e-4 ? 0.5 - angle * angle / 48.0 : std::sin(half) / angle;
  return Eigen::Quaterniond(
      std::cos(half), k * rotation_vector.x(), k * rotation_vector.y(), k * rotation_vector.z());
}

Eigen::Vector3d AxisAngleFromQuaternion(const Eigen::Quaterniond& rotation) {
  Eigen::Quaterniond q = rotation.normalized();
  if (q.w() < 0) q.coeffs() = -q.coeffs();  // angle in [0, pi]
  const double s = q.vec().norm();
  // angle = 2 atan2(|v|, w) is well conditioned everywhere, unlike acos(w).
  const double angle = 2.0 * std::atan2(s, q.w());
  const double k = s < 1e-8 ? 2.0 / q.w() : angle / s;
  return k * q.vec();
}

Eigen::Matrix3d CrossMatrix(const Eigen::Vector3d& v) {
  Eigen::Matrix3d k;
  k << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return k;
}

Eigen::Matrix3d RightJacobianSO3(const Eigen::Vector3d& rotation_vector) {
  const double a2 = rotation_vector.squaredNorm();
  const double a = std::sqrt(a2);
  // (1 - cos a)/a^2 = 1/2 - a^2/24 + ..., (a - sin a)/a^3 = 1/6 - a^2/120 + ...
  const double c1 = a < 1e-4 ? 0.5 - a2 / 24.0 : (1.0 - std::cos(a)) / a2;
  const double c2 = a < 1e-4 ? 1.0 / 6.0 - a2 / 120.0 : (a - std::sin(a)) / (a2 * a);
  const Eigen::Matrix3d k = CrossMatrix(rotation_vector);
  return Eigen::Matrix3d::Identity() - c1 * k + c2 * k * k;
}

Eigen::Matrix3d RotationFromAxisAngle(const Eigen::Vector3d& rotation_vector) {
  return QuaternionFromAxisAngle(rotation_vector).toRotationMatrix();
}

Eigen::Vector3d AxisAngleFromRotation(const Eigen::Matrix3d& rotation) {
  // Eigen's matrix -> quaternion conversion (Shepperd's method) is stable near pi.
  return AxisAngleFromQuaternion(Eigen::Quaterniond(rotation));
}

double RotationAngleBetween(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return AxisAngleFromQuaternion(a.conjugate() * b).norm();
}

double RotationAngleBetween(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return AxisAngleFromRotation(a.transpose() * b).norm();
}

Eigen::Matrix3d ProperRotationFromSvd(const Eigen::Matrix3d& left,
                                      const Eigen::Matrix3d& right,
                                      bool* reflected) {
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  const bool flip = (left * right.transpose()).determinant() < 0;
  if (flip) d(2, 2) = -1;
  if (reflected != nullptr) *reflected = flip;
  return left * d * right.transpose();
}

Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& matrix) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(matrix, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return ProperRotationFromSvd(svd.matrixU(), svd.matrixV());
}

std::optional<Eigen::Matrix3d> RotationFrom6d(const Eigen::Matrix<double, 6, 1>& columns) {
  const Eigen::Vector3d a = columns.head<3>();
  const Eigen::Vector3d b = columns.tail<3>();
  const double na = a.norm();
  if (!(na > 1e-12) || !b.allFinite()) return std::nullopt;
  const Eigen::Vector3d x = a / na;
  const Eigen::Vector3d b_perp = b - x.dot(b) * x;
  const double nb = b_perp.norm();
  if (!(nb > 1e-9 * std::max(1.0, b.norm()))) return std::nullopt;
  const Eigen::Vector3d y = b_perp / nb;
  Eigen::Matrix3d r;
  r.col(0) = x;
  r.col(1) = y;
  r.col(2) = x.cross(y);
  return r;
}

Eigen::Matrix<double, 6, 1> RotationTo6d(const Eigen::Matrix3d& rotation) {
  Eigen::Matrix<double, 6, 1> v;
  v << rotation.col(0), rotation.col(1);
  return v;
}

std::optional<Eigen::Quaterniond> AverageQuaternions(
    const std::vector<Eigen::Quaterniond>& rotations, const std::vector<double>& weights) {
  if (!weights.empty() && weights.size() != rotations.size()) {
    throw std::invalid_argument("AverageQuaternions: weights and rotations differ in size");
  }
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  double total = 0;
  for (size_t i = 0; i < rotations.size(); ++i) {
    const double w = weights.empty() ? 1.0 : weights[i];
    if (!(w >= 0) || !std::isfinite(w)) {
      throw std::invalid_argument("AverageQuaternions: weights must be finite and >= 0");
    }
    const Eigen::Vector4d q = rotations[i].normalized().coeffs();
    m += w * q * q.transpose();  // q q^T is the same for q and -q
    total += w;
  }
  if (!(total > 0)) return std::nullopt;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> solver(m / total);
  Eigen::Vector4d best = solver.eigenvectors().col(3);  // eigenvalues ascending
  if (best(3) < 0) best = -best;                        // coeffs() order is x y z w
  Eigen::Quaterniond q;
  q.coeffs() = best.normalized();
  return q;
}

Eigen::Matrix3d KabschRotation(const std::vector<Eigen::Vector3d>& a,
                               const std::vector<Eigen::Vector3d>& b) {
  if (a.size() != b.size()) throw std::invalid_argument("KabschRotation: sizes differ");
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < a.size(); ++i) h += a[i] * b[i].transpose();
  // R maximises tr(R h): V diag(1, 1, det) U^T for h = U S V^T.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return ProperRotationFromSvd(svd.matrixV(), svd.matrixU());
}

}  // namespace arco
