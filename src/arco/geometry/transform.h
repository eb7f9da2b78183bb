// Rigid and similarity transforms of 3D points, named by the frames they map
// between (COLMAP style): `Rigid3d cam_from_world` maps world points into the
// camera frame, p_cam = cam_from_world * p_world. Composition reads right to left:
// (a_from_b * b_from_c) = a_from_c.
//
// Rotations are stored as unit quaternions (Eigen, Hamilton convention) and kept
// normalised by every constructor and composition.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace arco {

// x -> R x + t.
struct Rigid3d {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3d() = default;
  Rigid3d(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation);
  // Throws std::invalid_argument unless `rotation` is a proper rotation matrix
  // (|R^T R - I| < 1e-6, det > 0).
  Rigid3d(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation);

  Eigen::Matrix3d RotationMatrix() const { return rotation.toRotationMatrix(); }
  // [R | t], 3x4.
  Eigen::Matrix<double, 3, 4> ToMatrix() const;
  Rigid3d Inverse() const;
  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const {
    return rotation * point + translation;
  }
  Rigid3d operator*(const Rigid3d& other) const;
};

// x -> R x + t with R held as a 3x3 matrix: the same map as Rigid3d for code whose
// numbers are matrix products throughout (synth's stage, the calibrations' poses), where
// a round trip through a quaternion would move the last bits of every output. Each
// operation is the plain matrix expression (no re-orthonormalisation), so composing and
// inverting gives exactly what the hand-written R, t code it replaces gave.
struct RigidMatrix3d {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  RigidMatrix3d() = default;
  // Takes `rotation` as given (no check): callers build it from a rotation.
  RigidMatrix3d(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation)
      : rotation(rotation), translation(translation) {}
  explicit RigidMatrix3d(const Rigid3d& rigid)
      : rotation(rigid.RotationMatrix()), translation(rigid.translation) {}

  // Throws std::invalid_argument unless `rotation` is a proper rotation matrix.
  Rigid3d ToRigid3d() const { return Rigid3d(rotation, translation); }
  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const {
    return rotation * point + translation;
  }
  RigidMatrix3d operator*(const RigidMatrix3d& other) const {
    return {rotation * other.rotation, rotation * other.translation + translation};
  }
  RigidMatrix3d Inverse() const {
    return {rotation.transpose(), -(rotation.transpose() * translation)};
  }
};

// x -> s R x + t with s > 0.
struct Sim3d {
  double scale = 1.0;
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Sim3d() = default;
  // Throws std::invalid_argument unless scale > 0 and finite.
  Sim3d(double scale, const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation);
  Sim3d(double scale, const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation);
  explicit Sim3d(const Rigid3d& rigid) : rotation(rigid.rotation), translation(rigid.translation) {}

  Eigen::Matrix3d RotationMatrix() const { return rotation.toRotationMatrix(); }
  // [s R | t], 3x4.
  Eigen::Matrix<double, 3, 4> ToMatrix() const;
  Sim3d Inverse() const;
  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const {
    return scale * (rotation * point) + translation;
  }
  Sim3d operator*(const Sim3d& other) const;
};

// x -> s R x + t with R held as a 3x3 matrix: Sim3d's map for code whose numbers are
// matrix products (the instrument's world_from_instrument, whose scale is world units per
// mm), as RigidMatrix3d is Rigid3d's. Each operation is the plain matrix expression.
struct SimMatrix3d {
  double scale = 1.0;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  SimMatrix3d() = default;
  // Takes the values as given (no check): callers build them from a rotation and a scale.
  SimMatrix3d(double scale, const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation)
      : scale(scale), rotation(rotation), translation(translation) {}
  explicit SimMatrix3d(const Sim3d& sim)
      : scale(sim.scale), rotation(sim.RotationMatrix()), translation(sim.translation) {}

  // Throws std::invalid_argument unless `rotation` is a proper rotation matrix and the
  // scale positive.
  Sim3d ToSim3d() const { return Sim3d(scale, rotation, translation); }
  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const {
    return scale * (rotation * point) + translation;
  }
  // The inverse map of one point, R^T (y - t) / s, without forming Inverse(): the
  // expression its callers have always computed, so their bits stay as they were.
  Eigen::Vector3d InverseMap(const Eigen::Vector3d& point) const {
    return rotation.transpose() * (point - translation) / scale;
  }
};

// Throws std::invalid_argument unless `rotation` is a proper rotation matrix.
void CheckRotationMatrix(const Eigen::Matrix3d& rotation, const char* what);

}  // namespace arco
