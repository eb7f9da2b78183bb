// Evaluation metrics of a motion-capture result against truth (docs/evaluation.md).
//
// Points are in millimetres, world frame, as frames x points x 3 with NaN for
// missing values, in the SPD/COCO-WholeBody layout (0-132 whole body, 91-111 left
// hand, 112-132 right hand, 133.. instrument points; DOMAIN.md section 3).
//
// The paper's protocol (Jin et al. 2024, section 7): hand MPJPE after aligning
// the wrists by translation; contact deviation = distance from the note-playing
// fingertip to the contact point, on frames where a note is pressed.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "arco/refine/bowing.h"
#include "arco/registry/keypoint_layout.h"

namespace arco::eval {

// The COCO-WholeBody offsets are the registry's (registry/keypoint_layout.h); the short
// names below are what the evaluation code and its tests use.
using wholebody::kLeftHandFirst;  // left-hand wrist
using wholebody::kRightHandFirst;
constexpr int kNumWholeBody = wholebody::kNumPoints;
constexpr int kNumHand = wholebody::kNumHandPoints;

// Hand keypoint (0..20) of a finger's joint: finger 1 = index .. 4 = little,
// 0 = thumb; joint 0 = MCP (thumb CMC) .. 3 = tip.
constexpr int HandJoint(int finger, int joint) { return 1 + 4 * finger + joint; }

// frames x points x 3, NaN = missing.
struct PointSequence {
  int num_frames = 0;
  int num_points = 0;
  std::vector<double> xyz;  // C order

  PointSequence() = default;
  PointSequence(int frames, int points);  // filled with NaN
  Eigen::Vector3d at(int frame, int point) const;
  void set(int frame, int point, const Eigen::Vector3d& p);
  bool valid(int frame, int point) const;  // all three finite
};

// Per-frame contact: which string is stopped by which finger where.
// string: 1 = highest string .. 4 = lowest, 0 = no pressed note (rest, open
// string, unvoiced). finger: 1 = index .. 4 = little, 0 = none.
struct ContactTrack {
  std::vector<int> string;
  std::vector<int> finger;
  std::vector<Eigen::Vector3d> point_mm;  // NaN when string == 0

  int num_frames() const { return static_cast<int>(string.size()); }
  bool pressed(int frame) const { return string[static_cast<size_t>(frame)] > 0; }
};

struct HandJointLimitsDeg {
  // Flexion ranges of the PIP (slot 0) and DIP (slot 1) joints per finger,
  // thumb first (the thumb's entries are ignored: its flexion axis cannot be
  // told from keypoints reliably); geometric angles measured from keypoints.
  double min_deg[5][2];
  double max_deg[5][2];
  // Geometric angle of each joint in the model's rest pose (all dofs zero),
  // subtracted before comparing: rest bones need not be collinear.
  double rest_deg[5][2] = {{0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}};
};

struct EvalOptions {
  std::vector<double> pck_thresholds_mm = {5, 10, 20};
  // Tolerance added to the joint limits before a geometric angle counts as a
  // violation: angles measured from keypoints carry the rest pose's small bends.
  double joint_limit_tolerance_deg = 2.0;
  std::optional<HandJointLimitsDeg> limits;  // absent: joint limits not evaluated
  int instrument_first = kNumWholeBody;      // first instrument point
  int num_instrument_points = 0;             // 0 = none
  // Points of the 13 SPD contact-stage extras (string ends), first index; -1 = none.
  int string_points_first = -1;
};

struct MethodMetrics {
  std::string method;
  int frames = 0;                     // frames with truth
  int contact_frames = 0;             // frames with a pressed note in the truth
  double mpjpe_hand_mm = NAN;         // left hand, wrist-aligned, 20 joints
  double mpjpe_note_finger_mm = NAN;  // MCP..tip of the truth's playing finger, contact frames
  double contact_deviation_mm = NAN;  // playing fingertip to truth contact point
  double contact_deviation_median_mm = NAN;
  std::vector<double> pck;       // per threshold, left hand wrist-aligned
  double string_accuracy = NAN;  // NaN when the method writes no contact annotation
  double finger_accuracy = NAN;
  int joint_limit_violations = -1;  // -1: not evaluated
  double mpjpe_body_mm = NAN;       // whole body 0..132, no alignment
  double instrument_error_mm = NAN;
  double string_error_mm = NAN;
  double missing_hand_fraction = 0;  // truth-valid hand joints the method left NaN
  // The left hand in the world, no alignment (where a user's animation puts it): all 21
  // joints, and by joint group: wrist, then the five fingers' base joints (thumb CMC, MCPs),
  // middle joints (thumb MCP, PIPs), distal joints (thumb IP, DIPs) and tips; and the truth's
  // playing fingertip on contact frames.
  double left_hand_world_mm = NAN;
  double left_group_world_mm[5] = {NAN, NAN, NAN, NAN, NAN};
  double playing_tip_world_mm = NAN;
  // The method's own contact point to the truth's, on frames where both press (needs a
  // contact annotation with points).
  double contact_point_error_mm = NAN;
  // The bow arm (refine/bowing.h) against a truth's bowing.csv (ScoreBowing); NaN when
  // either has none.
  double bow_direction_accuracy = NAN;
  double bow_string_accuracy = NAN;
  double sounding_point_error_mm = NAN;
  // Double stops (ScoreDoubleStops): over the truth's double-stop frames, the fraction
  // where the method's two strings (its two string-finger pairs) are the truth's, in
  // either voice order. NaN when the method gives no second note; written only when the
  // truth has double stops (double_stop_truth).
  bool double_stop_truth = false;
  int double_stop_frames = 0;
  double double_stop_string_accuracy = NAN;
  double double_stop_finger_accuracy = NAN;
  // Frames the method sounds two voices where the truth has one note or none (-1: the
  // method gives no second note).
  int false_double_stop_frames = -1;
  // Per frame (NaN where not measured): wrist-aligned left-hand error and
  // contact deviation, for plots.
  std::vector<double> frame_hand_mm, frame_contact_mm;
};

// Metrics of one method. `contact` may be null (the method writes none).
// Throws std::invalid_argument when the frame counts of truth and result differ.
MethodMetrics EvaluateMethod(const std::string& method,
                             const PointSequence& truth,
                             const ContactTrack& truth_contact,
                             const PointSequence& result,
                             const ContactTrack* result_contact,
                             const EvalOptions& options);

// Bow-arm metrics over the truth's sounding frames (string > 0): the direction where the
// truth moves the bow, the string under the bow (a double stop's second string counts),
// the sounding point's mean absolute error where the strings agree. Throws
// std::invalid_argument when the frame counts differ.
void ScoreBowing(const std::vector<refine::BowingFrame>& truth,
                 const std::vector<refine::BowingFrame>& method,
                 MethodMetrics* metrics);

// The notes sounding on one frame: up to two voices, each the string it sounds on (1 =
// highest; an open string too) and the finger stopping it (0 = open string); string 0: the
// voice is silent.
struct FrameVoices {
  int string[2] = {0, 0};
  int finger[2] = {0, 0};
  bool DoubleStop() const { return string[0] > 0 && string[1] > 0; }
};

// Double-stop metrics over the truth's frames with two voices: a string hit when the
// method's two strings are the truth's two, a finger hit when its two (string, finger)
// pairs are the truth's two, in either order (a method may call either voice its first).
// `method` null: the method gives no second note (accuracies stay NaN). Also counts the
// method's double stops on the truth's other frames (false_double_stop_frames). Sets
// double_stop_truth when the truth has a double-stop frame. Throws std::invalid_argument
// when the frame counts differ.
void ScoreDoubleStops(const std::vector<FrameVoices>& truth,
                      const std::vector<FrameVoices>* method,
                      MethodMetrics* metrics);

// Geometric flexion of a hand's PIP and DIP joints (degrees) from its 21
// keypoints, signed: positive bends towards the palm. The flexion axis is the
// hand's lateral axis, x = (index MCP - little MCP) for a right hand and its
// negative for a left hand (hand/hand_model.h: +x = distal x palmar in both
// hands), made orthogonal to the wrist -> middle MCP direction and, for each joint, to
// the bone proximal to it (the hinge is perpendicular to the bone it turns). NaN when a
// keypoint is missing. angles[finger][0] = PIP, [1] = DIP; thumb = MCP, IP.
void HandFlexionDeg(const Eigen::Vector3d hand[kNumHand], bool left, double angles[5][2]);

// Number of (frame, joint) pairs among the PIP and DIP joints of the index to
// little fingers (8 per frame) outside [min - tol, max + tol] after removing
// the rest angle.
int CountJointLimitViolations(const PointSequence& points,
                              int hand_first,
                              bool left,
                              const HandJointLimitsDeg& limits,
                              double tolerance_deg);

struct PitchMetrics {
  int frames = 0;  // scored frames
  int truth_voiced_frames = 0;
  double rpa50 = NAN;  // raw pitch accuracy within 50 cents, over truth-voiced frames
  double rpa25 = NAN;
  double voicing_recall = NAN;       // truth-voiced frames estimated voiced
  double voicing_false_alarm = NAN;  // truth-unvoiced frames estimated voiced
  double median_abs_cents = NAN;     // over frames voiced in both
};

// f0 in Hz per frame; <= 0 or NaN = unvoiced. `scored` (optional, same size)
// leaves frames out of every pitch metric, e.g. note attacks and release tails.
// Sizes must match (else throws).
PitchMetrics EvaluatePitch(const std::vector<double>& truth_f0_hz,
                           const std::vector<double>& estimate_f0_hz,
                           const std::vector<bool>* scored = nullptr);

}  // namespace arco::eval
