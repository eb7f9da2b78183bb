#include "arco/geometry/transform.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace arco {

void CheckRotationMatrix(const Eigen::Matrix3d& rotation, const char* what) {
  const double error =
      (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(error < 1e-6) || !(rotation.determinant() > 0)) {
    throw std::invalid_argument(std::string(what) + ": not a proper rotation matrix");
  }
}

Rigid3d::Rigid3d(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation)
    : rotation(rotation.normalized()), translation(translation) {}

Rigid3d::Rigid3d(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation)
    : translation(translation) {
  CheckRotationMatrix(rotation, "Rigid3d");
  this->rotation = Eigen::Quaterniond(rotation).normalized();
}

Eigen::Matrix<double, 3, 4> Rigid3d::ToMatrix() const {
  Eigen::Matrix<double, 3, 4> m;
  m.leftCols<3>() = RotationMatrix();
  m.col(3) = translation;
  return m;
}

Rigid3d Rigid3d::Inverse() const {
  const Eigen::Quaterniond inverse = rotation.conjugate();
  return Rigid3d(inverse, -(inverse * translation));
}

Rigid3d Rigid3d::operator*(const Rigid3d& other) const {
  return Rigid3d(rotation * other.rotation, rotation * other.translation + translation);
}

Sim3d::Sim3d(double scale, const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation)
    : scale(scale), rotation(rotation.normalized()), translation(translation) {
  if (!(scale > 0) || !std::isfinite(scale)) {
    throw std::invalid_argument("Sim3d: scale must be positive and finite");
  }
}

Sim3d::Sim3d(double scale, const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation)
    : Sim3d(scale, Eigen::Quaterniond::Identity(), translation) {
  CheckRotationMatrix(rotation, "Sim3d");
  this->rotation = Eigen::Quaterniond(rotation).normalized();
}

Eigen::Matrix<double, 3, 4> Sim3d::ToMatrix() const {
  Eigen::Matrix<double, 3, 4> m;
  m.leftCols<3>() = scale * RotationMatrix();
  m.col(3) = translation;
  return m;
}

Sim3d Sim3d::Inverse() const {
  // y = s R x + t  =>  x = (1/s) R^T y - (1/s) R^T t.
  const Eigen::Quaterniond inverse = rotation.conjugate();
  return Sim3d(1.0 / scale, inverse, -(inverse * translation) / scale);
}

Sim3d Sim3d::operator*(const Sim3d& other) const {
  // a(b(x)) = sa Ra (sb Rb x + tb) + ta.
  return Sim3d(scale * other.scale,
               rotation * other.rotation,
               scale * (rotation * other.translation) + translation);
}

}  // namespace arco
