#include "arco/hand/hand_model.h"

#include <Eigen/Geometry>
#include <cmath>
#include <sstream>

namespace arco::hand {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

const char* const kKeypointNames[kNumHandKeypoints] = {
    "wrist",     "thumb_cmc", "thumb_mcp",  "thumb_ip",   "thumb_tip",  "index_mcp",  "index_pip",
    "index_dip", "index_tip", "middle_mcp", "middle_pip", "middle_dip", "middle_tip", "ring_mcp",
    "ring_pip",  "ring_dip",  "ring_tip",   "little_mcp", "little_pip", "little_dip", "little_tip"};

const char* const kDofNames[kNumJointDofs] = {
    "thumb_cmc_flex",  "thumb_cmc_abd",   "thumb_mcp_flex", "thumb_ip_flex",   "index_mcp_flex",
    "index_mcp_abd",   "index_pip_flex",  "index_dip_flex", "middle_mcp_flex", "middle_mcp_abd",
    "middle_pip_flex", "middle_dip_flex", "ring_mcp_flex",  "ring_mcp_abd",    "ring_pip_flex",
    "ring_dip_flex",   "little_mcp_flex", "little_mcp_abd", "little_pip_flex", "little_dip_flex"};

// Unit vector `v` made orthogonal to unit `d`.
Eigen::Vector3d OrthogonalTo(const Eigen::Vector3d& v, const Eigen::Vector3d& d) {
  return (v - v.dot(d) * d).normalized();
}

// Joint axes of a right hand from its rest points (see the header for the
// sign conventions). Each flexion axis is perpendicular to the bone it moves.
std::array<Eigen::Vector3d, kNumJointDofs> RightHandAxes(const RestPointsMm& p) {
  const Eigen::Vector3d palmar = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d radial = Eigen::Vector3d::UnitX();
  std::array<Eigen::Vector3d, kNumJointDofs> axes;
  for (int f = 0; f < kNumFingers; ++f) {
    const Finger finger = static_cast<Finger>(f);
    const int k0 = KeypointIndex(finger, 0);
    const Eigen::Vector3d d0 = (p[k0 + 1] - p[k0]).normalized();
    const Eigen::Vector3d d1 = (p[k0 + 2] - p[k0 + 1]).normalized();
    const Eigen::Vector3d d2 = (p[k0 + 3] - p[k0 + 2]).normalized();
    if (finger == Finger::kThumb) {
      // CMC flexion turns the metacarpal about the palm normal towards the
      // little finger; palmar abduction lifts it out of the palm plane.
      const Eigen::Vector3d flex = OrthogonalTo(palmar, d0);
      axes[DofIndex(finger, FingerDof::kBaseFlex)] = flex;
      axes[DofIndex(finger, FingerDof::kBaseAbd)] = d0.cross(palmar).normalized();
      // The thumb pad faces ulnar-palmar; MCP/IP flexion curl towards it.
      const Eigen::Vector3d pad = (palmar - radial).normalized();
      axes[DofIndex(finger, FingerDof::kMiddleFlex)] = d1.cross(OrthogonalTo(pad, d1)).normalized();
      axes[DofIndex(finger, FingerDof::kDistalFlex)] = d2.cross(OrthogonalTo(pad, d2)).normalized();
    } else {
      // flexion axis = d x palmar moves d towards +z; abduction axis d x flex
      // (= -z for d = +y) moves the finger radially.
      const Eigen::Vector3d flex = d0.cross(OrthogonalTo(palmar, d0)).normalized();
      axes[DofIndex(finger, FingerDof::kBaseFlex)] = flex;
      axes[DofIndex(finger, FingerDof::kBaseAbd)] = d0.cross(flex).normalized();
      axes[DofIndex(finger, FingerDof::kMiddleFlex)] =
          d1.cross(OrthogonalTo(palmar, d1)).normalized();
      axes[DofIndex(finger, FingerDof::kDistalFlex)] =
          d2.cross(OrthogonalTo(palmar, d2)).normalized();
    }
  }
  return axes;
}

}  // namespace

const char* KeypointName(int k) {
  return (k >= 0 && k < kNumHandKeypoints) ? kKeypointNames[k] : "invalid";
}
const char* DofName(int dof) {
  return (dof >= 0 && dof < kNumJointDofs) ? kDofNames[dof] : "invalid";
}
const char* FingerName(Finger finger) {
  static const char* const kNames[kNumFingers] = {"thumb", "index", "middle", "ring", "little"};
  const int f = static_cast<int>(finger);
  return (f >= 0 && f < kNumFingers) ? kNames[f] : "invalid";
}
const char* HandSideName(HandSide side) { return side == HandSide::kLeft ? "left" : "right"; }

JointLimitsDeg DefaultJointLimitsDeg() {
  JointLimitsDeg limits;
  // Thumb (DOMAIN.md section 7 for MCP and IP; CMC from clinical ranges of the
  // trapeziometacarpal joint, measured from the flat-hand rest pose).
  limits[DofIndex(Finger::kThumb, FingerDof::kBaseFlex)] = {-25, 50};
  limits[DofIndex(Finger::kThumb, FingerDof::kBaseAbd)] = {-15, 60};
  limits[DofIndex(Finger::kThumb, FingerDof::kMiddleFlex)] = {-10, 55};
  limits[DofIndex(Finger::kThumb, FingerDof::kDistalFlex)] = {-15, 80};
  for (int f = 1; f < kNumFingers; ++f) {
    const Finger finger = static_cast<Finger>(f);
    limits[DofIndex(finger, FingerDof::kBaseFlex)] = {-30, 90};    // MCP, 30 hyperextension
    limits[DofIndex(finger, FingerDof::kBaseAbd)] = {-20, 20};     // MCP abduction
    // PIP and DIP: real players hyperextend them when a fingertip presses a string (the
    // DIP collapses under the string's force). On SPD's real cello01 take, the former
    // {0, 110} and {-10, 90} were violated by 131 (frame, joint) pairs; these ranges by
    // none (docs/hand.md, "Joint limits on a real hand").
    limits[DofIndex(finger, FingerDof::kMiddleFlex)] = {-10, 110};  // PIP
    limits[DofIndex(finger, FingerDof::kDistalFlex)] = {-30, 90};   // DIP
  }
  return limits;
}

RestPointsMm DefaultRightRestPointsMm() {
  // Bone directions (unnormalised) and lengths of an average adult right hand
  // (DOMAIN.md section 7): wrist->MCP 88/87/84/80, phalanges as listed there.
  struct Bone {
    Eigen::Vector3d direction;
    double length_mm;
  };
  const Bone kWristToBase[kNumFingers] = {{{0.62, 0.75, 0.22}, 36},
                                          {{0.28, 1.0, 0.0}, 88},
                                          {{0.04, 1.0, 0.0}, 87},
                                          {{-0.18, 1.0, 0.03}, 84},
                                          {{-0.38, 1.0, 0.08}, 80}};
  const Eigen::Vector3d kFingerDir[kNumFingers] = {
      {0.70, 0.68, 0.22}, {0.10, 1.0, 0.0}, {0.0, 1.0, 0.0}, {-0.07, 1.0, 0.0}, {-0.15, 1.0, 0.0}};
  const double kPhalanxMm[kNumFingers][3] = {
      {42, 32, 27}, {42, 25, 21}, {45, 29, 22}, {42, 27, 22}, {33, 20, 19}};
  RestPointsMm points;
  points[0].setZero();
  for (int f = 0; f < kNumFingers; ++f) {
    const Finger finger = static_cast<Finger>(f);
    const int k0 = KeypointIndex(finger, 0);
    points[k0] = kWristToBase[f].direction.normalized() * kWristToBase[f].length_mm;
    const Eigen::Vector3d d = kFingerDir[f].normalized();
    for (int j = 1; j <= 3; ++j) points[k0 + j] = points[k0 + j - 1] + kPhalanxMm[f][j - 1] * d;
  }
  return points;
}

HandModel HandModel::Default(HandSide side) {
  StatusOr<HandModel> model = Create(side, DefaultRightRestPointsMm(), DefaultJointLimitsDeg());
  ARCO_CHECK(model.ok()) << model.status().message();
  return std::move(model).value();
}

StatusOr<HandModel> HandModel::Create(HandSide side,
                                      const RestPointsMm& right_rest_points_mm,
                                      const JointLimitsDeg& limits_deg) {
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    if (!right_rest_points_mm[k].allFinite()) {
      return Status::Error(std::string("hand model: rest point ") + KeypointName(k) +
                           " is not finite");
    }
    if (k > 0 && (right_rest_points_mm[k] - right_rest_points_mm[ParentKeypoint(k)]).norm() < 1.0) {
      return Status::Error(std::string("hand model: bone to ") + KeypointName(k) +
                           " is shorter than 1 mm");
    }
  }
  for (int d = 0; d < kNumJointDofs; ++d) {
    const JointLimitDeg& l = limits_deg[d];
    if (!std::isfinite(l.min_deg) || !std::isfinite(l.max_deg) || l.min_deg > l.max_deg) {
      std::ostringstream msg;
      msg << "hand model: limit of " << DofName(d) << " [" << l.min_deg << ", " << l.max_deg
          << "] deg is not a finite interval";
      return Status::Error(msg.str());
    }
  }
  HandModel model;
  model.side_ = side;
  model.right_rest_points_mm_ = right_rest_points_mm;
  model.limits_deg_ = limits_deg;
  // Mirror for the left hand: points p -> M p, axes (pseudovectors) a -> -M a,
  // so that the same angles give the mirror-image pose.
  const Eigen::Vector3d m =
      side == HandSide::kLeft ? Eigen::Vector3d(-1, 1, 1) : Eigen::Vector3d(1, 1, 1);
  const double pseudo = side == HandSide::kLeft ? -1.0 : 1.0;
  model.rest_offset_mm_[0].setZero();
  for (int k = 1; k < kNumHandKeypoints; ++k) {
    model.rest_offset_mm_[k] =
        m.cwiseProduct(right_rest_points_mm[k] - right_rest_points_mm[ParentKeypoint(k)]);
  }
  const auto right_axes = RightHandAxes(right_rest_points_mm);
  for (int d = 0; d < kNumJointDofs; ++d) {
    model.axis_[d] = pseudo * m.cwiseProduct(right_axes[d]);
    model.min_rad_[d] = limits_deg[d].min_deg * kDegToRad;
    model.max_rad_[d] = limits_deg[d].max_deg * kDegToRad;
  }
  return model;
}

StatusOr<HandModel> HandModel::WithBoneLengths(const BoneLengthsMm& lengths_mm) const {
  RestPointsMm points;
  points[0] = right_rest_points_mm_[0];
  for (int k = 1; k < kNumHandKeypoints; ++k) {
    if (!std::isfinite(lengths_mm[k]) || lengths_mm[k] < 1.0) {
      std::ostringstream msg;
      msg << "hand model: bone length to " << KeypointName(k) << " (" << lengths_mm[k]
          << " mm) is not a finite length >= 1 mm";
      return Status::Error(msg.str());
    }
    const int parent = ParentKeypoint(k);
    const Eigen::Vector3d d =
        (right_rest_points_mm_[k] - right_rest_points_mm_[parent]).normalized();
    points[k] = points[parent] + lengths_mm[k] * d;  // parents come first in the order
  }
  return Create(side_, points, limits_deg_);
}

StatusOr<HandModel> HandModel::WithRestPoints(const RestPointsMm& points_in_wrist_mm) const {
  // Back to the right-hand convention Create takes (x mirrored for a left hand).
  const Eigen::Vector3d m =
      side_ == HandSide::kLeft ? Eigen::Vector3d(-1, 1, 1) : Eigen::Vector3d(1, 1, 1);
  RestPointsMm right;
  for (int k = 0; k < kNumHandKeypoints; ++k) right[k] = m.cwiseProduct(points_in_wrist_mm[k]);
  return Create(side_, right, limits_deg_);
}

StatusOr<HandModel> HandModel::WithBasePoints(
    const std::array<Eigen::Vector3d, kNumFingers>& base_in_wrist_mm) const {
  RestPointsMm points = rest_points_mm();
  for (int f = 0; f < kNumFingers; ++f) {
    const int k0 = KeypointIndex(static_cast<Finger>(f), 0);
    const Eigen::Vector3d shift = base_in_wrist_mm[f] - points[k0];
    for (int j = 0; j < 4; ++j) points[k0 + j] += shift;
  }
  return WithRestPoints(points);
}

HandModel HandModel::Mirrored() const {
  StatusOr<HandModel> model = Create(side_ == HandSide::kLeft ? HandSide::kRight : HandSide::kLeft,
                                     right_rest_points_mm_,
                                     limits_deg_);
  ARCO_CHECK(model.ok()) << model.status().message();
  return std::move(model).value();
}

Eigen::Vector3d HandModel::rest_point_mm(int k) const {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (int j = k; j > 0; j = ParentKeypoint(j)) p += rest_offset_mm_[j];
  return p;
}

BoneLengthsMm HandModel::bone_lengths_mm() const {
  BoneLengthsMm lengths{};
  for (int k = 1; k < kNumHandKeypoints; ++k) lengths[k] = bone_length_mm(k);
  return lengths;
}

RestPointsMm HandModel::rest_points_mm() const {
  // Mirroring is exact, so WithRestPoints(rest_points_mm()) is this model bit for bit.
  const Eigen::Vector3d m =
      side_ == HandSide::kLeft ? Eigen::Vector3d(-1, 1, 1) : Eigen::Vector3d(1, 1, 1);
  RestPointsMm points;
  for (int k = 0; k < kNumHandKeypoints; ++k) points[k] = m.cwiseProduct(right_rest_points_mm_[k]);
  return points;
}

Eigen::Vector3d HandPose::WristAngleAxis() const {
  const Eigen::AngleAxisd aa(world_from_wrist.rotation);
  return aa.angle() * aa.axis();
}

void HandPose::SetWristAngleAxis(const Eigen::Vector3d& angle_axis) {
  const double angle = angle_axis.norm();
  world_from_wrist.rotation = angle < 1e-300
                                  ? Eigen::Matrix3d::Identity()
                                  : Eigen::AngleAxisd(angle, angle_axis / angle).toRotationMatrix();
}

int CountLimitViolations(const HandModel& model, const HandPose& pose, double tolerance_rad) {
  int count = 0;
  for (int d = 0; d < kNumJointDofs; ++d) {
    const double a = pose.angles_rad[d];
    if (!(a >= model.min_rad(d) - tolerance_rad && a <= model.max_rad(d) + tolerance_rad)) ++count;
  }
  return count;
}

HandPose ClampToLimits(const HandModel& model, const HandPose& pose) {
  HandPose out = pose;
  for (int d = 0; d < kNumJointDofs; ++d) {
    double& a = out.angles_rad[d];
    if (std::isnan(a)) a = 0.0;
    a = std::min(std::max(a, model.min_rad(d)), model.max_rad(d));
  }
  return out;
}

}  // namespace arco::hand
