// arco's hand model: a 21-keypoint kinematic tree in the COCO-WholeBody hand
// order (no MANO). The immutable HandModel holds topology, rest-pose bone offsets,
// bone lengths, joint axes and limits; the per-frame HandPose holds the wrist pose
// and 20 joint angles (Pinocchio's model/data split).
//
// Keypoints: 0 wrist; thumb 1-4 (CMC, MCP, IP, tip); index 5-8 (MCP, PIP, DIP,
// tip); middle 9-12; ring 13-16; little 17-20.
//
// Wrist frame (all rest offsets and axes are given in it), millimetres:
//   origin at the wrist keypoint, +y distal (towards the middle MCP),
//   +z palmar (out of the palm), +x = y cross z. For a RIGHT hand +x points
//   radially (towards the thumb); a LEFT hand is the mirror image (x -> -x), so
//   its thumb lies at negative x. Both frames are proper right-handed frames.
//
// Joint angles (radians, 4 per finger, DofIndex(finger, slot)):
//   slot 0 kBaseFlex:   MCP flexion (thumb: CMC flexion, across the palm)
//   slot 1 kBaseAbd:    MCP abduction, positive towards the thumb side
//                       (thumb: CMC palmar abduction, away from the palm plane)
//   slot 2 kMiddleFlex: PIP flexion (thumb: MCP flexion)
//   slot 3 kDistalFlex: DIP flexion (thumb: IP flexion)
// Positive flexion curls towards the palm in both hands (mirrored axes are
// pseudovectors: a_left = -M a_right with M = diag(-1, 1, 1)).
// The base joint is a universal joint: R_base = R(a_abd, abd) * R(a_flex, flex),
// the abduction axis fixed to the palm, the flexion axis carried by abduction.
// All angles zero is the rest pose (flat hand, thumb in the palm plane).
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>

#include "arco/geometry/transform.h"
#include "arco/util/status.h"

namespace arco::hand {

constexpr int kNumHandKeypoints = 21;
constexpr int kNumFingers = 5;
constexpr int kNumJointDofs = 20;

enum class HandSide { kLeft, kRight };
enum class Finger { kThumb = 0, kIndex = 1, kMiddle = 2, kRing = 3, kLittle = 4 };
enum class FingerDof { kBaseFlex = 0, kBaseAbd = 1, kMiddleFlex = 2, kDistalFlex = 3 };

constexpr int DofIndex(Finger finger, FingerDof dof) {
  return 4 * static_cast<int>(finger) + static_cast<int>(dof);
}
// j = 0 base joint (MCP / thumb CMC) ... 3 tip.
constexpr int KeypointIndex(Finger finger, int j) { return 1 + 4 * static_cast<int>(finger) + j; }
constexpr int TipKeypoint(Finger finger) { return KeypointIndex(finger, 3); }
// Parent in the kinematic tree; -1 for the wrist.
constexpr int ParentKeypoint(int k) { return k == 0 ? -1 : ((k - 1) % 4 == 0 ? 0 : k - 1); }

const char* KeypointName(int k);  // "wrist", "index_pip", ...
const char* DofName(int dof);     // "index_mcp_flex", "thumb_cmc_abd", ...
const char* FingerName(Finger finger);
const char* HandSideName(HandSide side);

struct JointLimitDeg {
  double min_deg = 0;
  double max_deg = 0;
};
using JointLimitsDeg = std::array<JointLimitDeg, kNumJointDofs>;

// Documented default limits (docs/hand.md, DOMAIN.md section 7): clinical
// ranges of motion, slightly generous so that real performers fit.
JointLimitsDeg DefaultJointLimitsDeg();

// Keypoint positions of a right hand in the rest pose, wrist frame, mm.
using RestPointsMm = std::array<Eigen::Vector3d, kNumHandKeypoints>;
RestPointsMm DefaultRightRestPointsMm();

// Bone lengths indexed by child keypoint (entry 0, the wrist, is unused).
using BoneLengthsMm = std::array<double, kNumHandKeypoints>;

class HandModel {
 public:
  // An average adult hand (DOMAIN.md section 7) with the default limits.
  static HandModel Default(HandSide side);
  // `right_rest_points_mm` follow the right-hand convention (thumb at +x); a
  // left model mirrors them. Errors on non-finite points, bones shorter than
  // 1 mm, or limits with min > max.
  static StatusOr<HandModel> Create(HandSide side,
                                    const RestPointsMm& right_rest_points_mm,
                                    const JointLimitsDeg& limits_deg);
  // Same directions and limits, new bone lengths (per-performer model).
  StatusOr<HandModel> WithBoneLengths(const BoneLengthsMm& lengths_mm) const;
  // Same side and limits, the rest pose given as points in this model's own wrist frame
  // (for a left model, the mirrored points rest_point_mm gives): the per-performer model
  // a result folder stores (hand/rest_points_mm.npy). Errors as Create.
  StatusOr<HandModel> WithRestPoints(const RestPointsMm& points_in_wrist_mm) const;
  // Same fingers and limits, each finger's base (thumb CMC, index..little MCP) moved to
  // `base_in_wrist_mm` (this model's wrist frame) with its chain: the performer's palm
  // (palm_shape.h). The joint axes depend on the finger bones only, so they are kept.
  StatusOr<HandModel> WithBasePoints(
      const std::array<Eigen::Vector3d, kNumFingers>& base_in_wrist_mm) const;
  HandModel Mirrored() const;  // the other hand, same lengths and limits

  HandSide side() const { return side_; }
  // Rest-pose offset of keypoint k from its parent, wrist frame, mm.
  const Eigen::Vector3d& rest_offset_mm(int k) const { return rest_offset_mm_[k]; }
  Eigen::Vector3d rest_point_mm(int k) const;  // rest-pose position, wrist frame
  double bone_length_mm(int k) const { return rest_offset_mm_[k].norm(); }
  BoneLengthsMm bone_lengths_mm() const;
  // The rest points this model was made from, in its own wrist frame (the right-hand
  // points, mirrored for a left hand): WithRestPoints(rest_points_mm()) is this model.
  RestPointsMm rest_points_mm() const;
  // Unit joint axis of a dof in its parent's rest frame (= wrist frame at rest).
  const Eigen::Vector3d& axis(int dof) const { return axis_[dof]; }
  double min_rad(int dof) const { return min_rad_[dof]; }
  double max_rad(int dof) const { return max_rad_[dof]; }
  const JointLimitsDeg& limits_deg() const { return limits_deg_; }
  // The right-hand-convention rest points this model was built from.
  const RestPointsMm& right_rest_points_mm() const { return right_rest_points_mm_; }

 private:
  HandModel() = default;
  HandSide side_ = HandSide::kRight;
  RestPointsMm right_rest_points_mm_;
  JointLimitsDeg limits_deg_;
  std::array<Eigen::Vector3d, kNumHandKeypoints> rest_offset_mm_;
  std::array<Eigen::Vector3d, kNumJointDofs> axis_;
  std::array<double, kNumJointDofs> min_rad_, max_rad_;
};

// Per-frame state. world_from_wrist maps wrist-frame mm into world mm: its translation is
// the wrist's position in the world, mm.
struct HandPose {
  RigidMatrix3d world_from_wrist;
  std::array<double, kNumJointDofs> angles_rad{};

  double angle_rad(Finger f, FingerDof d) const { return angles_rad[DofIndex(f, d)]; }
  double& angle_rad(Finger f, FingerDof d) { return angles_rad[DofIndex(f, d)]; }
  // Wrist rotation as an angle-axis vector (the optimisers' parameterisation).
  Eigen::Vector3d WristAngleAxis() const;
  void SetWristAngleAxis(const Eigen::Vector3d& angle_axis);
};

// Number of dofs outside [min, max] by more than tolerance_rad (NaN counts).
int CountLimitViolations(const HandModel& model, const HandPose& pose, double tolerance_rad = 1e-9);
// Clamps every angle into its limits (NaN -> the nearest limit to zero).
HandPose ClampToLimits(const HandModel& model, const HandPose& pose);

}  // namespace arco::hand
