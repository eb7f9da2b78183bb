#include "arco/eval/metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "arco/util/stats.h"

namespace arco::eval {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kRadToDeg = 57.29577951308232;

double Mean(const std::vector<double>& v) {
  if (v.empty()) return kNaN;
  double s = 0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

bool Finite(const Eigen::Vector3d& p) { return p.allFinite(); }

// Signed angle from bone u to bone v about unit `axis` (degrees), measured in
// the plane perpendicular to the axis (out-of-plane deviation is ignored).
double SignedBendDeg(const Eigen::Vector3d& u,
                     const Eigen::Vector3d& v,
                     const Eigen::Vector3d& axis) {
  const Eigen::Vector3d up = u - u.dot(axis) * axis;
  const Eigen::Vector3d vp = v - v.dot(axis) * axis;
  const double s = up.cross(vp).dot(axis);
  const double c = up.dot(vp);
  return std::atan2(s, c) * kRadToDeg;
}

}  // namespace

PointSequence::PointSequence(int frames, int points)
    : num_frames(frames),
      num_points(points),
      xyz(static_cast<size_t>(frames) * static_cast<size_t>(points) * 3, kNaN) {}

Eigen::Vector3d PointSequence::at(int frame, int point) const {
  const size_t i =
      (static_cast<size_t>(frame) * static_cast<size_t>(num_points) + static_cast<size_t>(point)) *
      3;
  return {xyz[i], xyz[i + 1], xyz[i + 2]};
}

void PointSequence::set(int frame, int point, const Eigen::Vector3d& p) {
  const size_t i =
      (static_cast<size_t>(frame) * static_cast<size_t>(num_points) + static_cast<size_t>(point)) *
      3;
  xyz[i] = p.x();
  xyz[i + 1] = p.y();
  xyz[i + 2] = p.z();
}

bool PointSequence::valid(int frame, int point) const { return Finite(at(frame, point)); }

void HandFlexionDeg(const Eigen::Vector3d hand[kNumHand], bool left, double angles[5][2]) {
  for (int f = 0; f < 5; ++f) angles[f][0] = angles[f][1] = kNaN;
  const Eigen::Vector3d& wrist = hand[0];
  const Eigen::Vector3d& index_mcp = hand[HandJoint(1, 0)];
  const Eigen::Vector3d& middle_mcp = hand[HandJoint(2, 0)];
  const Eigen::Vector3d& little_mcp = hand[HandJoint(4, 0)];
  if (!Finite(wrist) || !Finite(index_mcp) || !Finite(middle_mcp) || !Finite(little_mcp)) return;
  const Eigen::Vector3d distal = (middle_mcp - wrist).normalized();
  Eigen::Vector3d lateral = (left ? -1.0 : 1.0) * (index_mcp - little_mcp);
  lateral -= lateral.dot(distal) * distal;
  if (!(lateral.norm() > 1e-9)) return;
  lateral.normalize();
  for (int f = 0; f < 5; ++f) {
    const Eigen::Vector3d& a = hand[HandJoint(f, 0)];
    const Eigen::Vector3d& b = hand[HandJoint(f, 1)];
    const Eigen::Vector3d& c = hand[HandJoint(f, 2)];
    const Eigen::Vector3d& d = hand[HandJoint(f, 3)];
    // Each bend about the lateral axis made orthogonal to its proximal bone: a hinge
    // perpendicular to the bone it turns (hand_model.cc, RightHandAxes), so an abducted
    // finger or a palm whose MCP line is not square to the fingers (a performer's own
    // palm, hand/palm_shape.h) does not tilt the measured bend.
    const auto bend = [&](const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
      Eigen::Vector3d axis = lateral - lateral.dot(u.normalized()) * u.normalized();
      if (!(axis.norm() > 1e-9)) return kNaN;
      return SignedBendDeg(u, v, axis.normalized());
    };
    if (Finite(a) && Finite(b) && Finite(c)) angles[f][0] = bend(b - a, c - b);
    if (Finite(b) && Finite(c) && Finite(d)) angles[f][1] = bend(c - b, d - c);
  }
}

int CountJointLimitViolations(const PointSequence& points,
                              int hand_first,
                              bool left,
                              const HandJointLimitsDeg& limits,
                              double tolerance_deg) {
  if (hand_first + kNumHand > points.num_points) {
    throw std::invalid_argument("CountJointLimitViolations: hand outside the point layout");
  }
  int violations = 0;
  Eigen::Vector3d hand[kNumHand];
  for (int fr = 0; fr < points.num_frames; ++fr) {
    for (int k = 0; k < kNumHand; ++k) hand[k] = points.at(fr, hand_first + k);
    double angles[5][2];
    HandFlexionDeg(hand, left, angles);
    for (int f = 1; f < 5; ++f) {
      for (int j = 0; j < 2; ++j) {
        if (std::isnan(angles[f][j])) continue;
        const double a = angles[f][j] - limits.rest_deg[f][j];
        if (a < limits.min_deg[f][j] - tolerance_deg || a > limits.max_deg[f][j] + tolerance_deg) {
          ++violations;
        }
      }
    }
  }
  return violations;
}

MethodMetrics EvaluateMethod(const std::string& method,
                             const PointSequence& truth,
                             const ContactTrack& truth_contact,
                             const PointSequence& result,
                             const ContactTrack* result_contact,
                             const EvalOptions& options) {
  if (truth.num_frames != result.num_frames) {
    throw std::invalid_argument("EvaluateMethod: truth has " + std::to_string(truth.num_frames) +
                                " frames, result " + std::to_string(result.num_frames));
  }
  if (truth_contact.num_frames() != truth.num_frames) {
    throw std::invalid_argument("EvaluateMethod: truth contact track length differs");
  }
  if (result_contact && result_contact->num_frames() != truth.num_frames) {
    throw std::invalid_argument("EvaluateMethod: result contact track length differs");
  }
  const int num_points = std::min(truth.num_points, result.num_points);
  MethodMetrics m;
  m.method = method;
  std::vector<double> world_hand_err, world_group_err[5], playing_tip_err, contact_point_err;
  std::vector<double> hand_err, finger_err, contact_err, body_err, instrument_err, string_err;
  std::vector<int> pck_hits(options.pck_thresholds_mm.size(), 0);
  int hand_truth_valid = 0, hand_missing = 0, string_hits = 0, finger_hits = 0;
  m.frame_hand_mm.assign(static_cast<size_t>(truth.num_frames), kNaN);
  m.frame_contact_mm.assign(static_cast<size_t>(truth.num_frames), kNaN);
  for (int fr = 0; fr < truth.num_frames; ++fr) {
    double frame_sum = 0;
    int frame_count = 0;
    bool any_truth = false;  // any truth point at all in this frame
    for (int p = 0; p < truth.num_points && !any_truth; ++p) any_truth = truth.valid(fr, p);
    // Whole body without alignment.
    for (int p = 0; p < std::min(num_points, kNumWholeBody); ++p) {
      if (!truth.valid(fr, p)) continue;
      if (result.valid(fr, p)) body_err.push_back((truth.at(fr, p) - result.at(fr, p)).norm());
    }
    // Left hand in the world, by joint group (k = 0 wrist, then 1 + 4 finger + joint).
    const int w = kLeftHandFirst;
    for (int k = 0; k < kNumHand && w + k < num_points; ++k) {
      if (!truth.valid(fr, w + k) || !result.valid(fr, w + k)) continue;
      const double e = (truth.at(fr, w + k) - result.at(fr, w + k)).norm();
      world_hand_err.push_back(e);
      world_group_err[k == 0 ? 0 : 1 + (k - 1) % 4].push_back(e);
    }
    // Left hand after aligning the wrists by translation (the paper's protocol).
    const bool wrists = w < num_points && truth.valid(fr, w) && result.valid(fr, w);
    const Eigen::Vector3d shift =
        wrists ? Eigen::Vector3d(truth.at(fr, w) - result.at(fr, w)) : Eigen::Vector3d::Zero();
    for (int k = 1; k < kNumHand && w + k < num_points; ++k) {
      if (!truth.valid(fr, w + k)) continue;
      ++hand_truth_valid;
      if (!wrists || !result.valid(fr, w + k)) {
        ++hand_missing;
        continue;
      }
      const double e = (truth.at(fr, w + k) - (result.at(fr, w + k) + shift)).norm();
      hand_err.push_back(e);
      frame_sum += e;
      ++frame_count;
      for (size_t t = 0; t < options.pck_thresholds_mm.size(); ++t) {
        if (e <= options.pck_thresholds_mm[t]) ++pck_hits[t];
      }
    }
    // Instrument points and string ends, no alignment.
    for (int i = 0; i < options.num_instrument_points; ++i) {
      const int p = options.instrument_first + i;
      if (p < num_points && truth.valid(fr, p) && result.valid(fr, p)) {
        instrument_err.push_back((truth.at(fr, p) - result.at(fr, p)).norm());
      }
    }
    if (options.string_points_first >= 0) {
      for (int i = 0; i < 8; ++i) {
        const int p = options.string_points_first + i;
        if (p < num_points && truth.valid(fr, p) && result.valid(fr, p)) {
          string_err.push_back((truth.at(fr, p) - result.at(fr, p)).norm());
        }
      }
    }
    if (any_truth) ++m.frames;
    if (frame_count > 0) m.frame_hand_mm[static_cast<size_t>(fr)] = frame_sum / frame_count;
    // Contact metrics only on frames where the truth presses a note.
    if (!truth_contact.pressed(fr)) continue;
    ++m.contact_frames;
    const int finger = truth_contact.finger[static_cast<size_t>(fr)];
    const int tip = w + HandJoint(finger, 3);
    if (tip < num_points && result.valid(fr, tip) && truth.valid(fr, tip))
      playing_tip_err.push_back((result.at(fr, tip) - truth.at(fr, tip)).norm());
    if (tip < num_points && result.valid(fr, tip)) {
      contact_err.push_back(
          (result.at(fr, tip) - truth_contact.point_mm[static_cast<size_t>(fr)]).norm());
      m.frame_contact_mm[static_cast<size_t>(fr)] = contact_err.back();
    }
    if (wrists) {
      for (int j = 0; j < 4; ++j) {
        const int p = w + HandJoint(finger, j);
        if (p < num_points && truth.valid(fr, p) && result.valid(fr, p)) {
          finger_err.push_back((truth.at(fr, p) - (result.at(fr, p) + shift)).norm());
        }
      }
    }
    if (result_contact) {
      const size_t i = static_cast<size_t>(fr);
      string_hits += result_contact->string[i] == truth_contact.string[i];
      if (result_contact->pressed(fr) && result_contact->point_mm[i].allFinite())
        contact_point_err.push_back(
            (result_contact->point_mm[i] - truth_contact.point_mm[i]).norm());
      finger_hits += result_contact->finger[i] == truth_contact.finger[i];
    }
  }
  m.mpjpe_hand_mm = Mean(hand_err);
  m.left_hand_world_mm = Mean(world_hand_err);
  for (int g = 0; g < 5; ++g) m.left_group_world_mm[g] = Mean(world_group_err[g]);
  m.playing_tip_world_mm = Mean(playing_tip_err);
  m.contact_point_error_mm = Mean(contact_point_err);
  m.mpjpe_note_finger_mm = Mean(finger_err);
  m.contact_deviation_mm = Mean(contact_err);
  m.contact_deviation_median_mm = Median(contact_err);
  m.mpjpe_body_mm = Mean(body_err);
  m.instrument_error_mm = Mean(instrument_err);
  m.string_error_mm = Mean(string_err);
  m.missing_hand_fraction =
      hand_truth_valid > 0 ? static_cast<double>(hand_missing) / hand_truth_valid : 0.0;
  const double denom = static_cast<double>(hand_truth_valid);
  for (int hits : pck_hits) m.pck.push_back(denom > 0 ? hits / denom : kNaN);
  if (result_contact && m.contact_frames > 0) {
    m.string_accuracy = static_cast<double>(string_hits) / m.contact_frames;
    m.finger_accuracy = static_cast<double>(finger_hits) / m.contact_frames;
  }
  if (options.limits && kLeftHandFirst + kNumHand <= result.num_points) {
    m.joint_limit_violations = CountJointLimitViolations(
        result, kLeftHandFirst, true, *options.limits, options.joint_limit_tolerance_deg);
  }
  return m;
}

PitchMetrics EvaluatePitch(const std::vector<double>& truth_f0_hz,
                           const std::vector<double>& estimate_f0_hz,
                           const std::vector<bool>* scored) {
  if (truth_f0_hz.size() != estimate_f0_hz.size() ||
      (scored && scored->size() != truth_f0_hz.size())) {
    throw std::invalid_argument("EvaluatePitch: truth, estimate and mask differ in length");
  }
  PitchMetrics m;
  int hit50 = 0, hit25 = 0, recalled = 0, unvoiced = 0, false_alarms = 0;
  std::vector<double> abs_cents;
  for (size_t i = 0; i < truth_f0_hz.size(); ++i) {
    if (scored && !(*scored)[i]) continue;
    ++m.frames;
    const bool tv = truth_f0_hz[i] > 0;  // false for NaN too
    const bool ev = estimate_f0_hz[i] > 0;
    if (!tv) {
      ++unvoiced;
      false_alarms += ev;
      continue;
    }
    ++m.truth_voiced_frames;
    if (!ev) continue;
    ++recalled;
    const double cents = std::abs(1200.0 * std::log2(estimate_f0_hz[i] / truth_f0_hz[i]));
    abs_cents.push_back(cents);
    hit50 += cents <= 50.0;
    hit25 += cents <= 25.0;
  }
  // RPA counts an unvoiced estimate on a voiced frame as a miss (MIREX convention).
  if (m.truth_voiced_frames > 0) {
    m.rpa50 = static_cast<double>(hit50) / m.truth_voiced_frames;
    m.rpa25 = static_cast<double>(hit25) / m.truth_voiced_frames;
    m.voicing_recall = static_cast<double>(recalled) / m.truth_voiced_frames;
  }
  if (unvoiced > 0) m.voicing_false_alarm = static_cast<double>(false_alarms) / unvoiced;
  m.median_abs_cents = Median(abs_cents);
  return m;
}

void ScoreBowing(const std::vector<refine::BowingFrame>& truth,
                 const std::vector<refine::BowingFrame>& method,
                 MethodMetrics* metrics) {
  if (truth.size() != method.size()) {
    throw std::invalid_argument("bowing: " + std::to_string(method.size()) +
                                " frames but the truth has " + std::to_string(truth.size()));
  }
  int sounding = 0, string_right = 0, moving = 0, direction_right = 0, sp_count = 0;
  double sp_sum = 0;
  for (size_t f = 0; f < truth.size(); ++f) {
    const refine::BowingFrame& t = truth[f];
    const refine::BowingFrame& m = method[f];
    if (t.string <= 0) continue;
    ++sounding;
    // A string the truth's bow is on (a double stop's bow is on two) is under the method's.
    const auto bowed = [&t](int s) { return s > 0 && (s == t.string || s == t.second_string); };
    const bool same_string = bowed(m.string) || bowed(m.second_string);
    string_right += same_string;
    if (t.direction != refine::BowDirection::kNone) {
      ++moving;
      direction_right += m.direction == t.direction;
    }
    if (same_string && std::isfinite(m.sounding_point_mm) && std::isfinite(t.sounding_point_mm)) {
      sp_sum += std::abs(m.sounding_point_mm - t.sounding_point_mm);
      ++sp_count;
    }
  }
  if (sounding > 0) metrics->bow_string_accuracy = static_cast<double>(string_right) / sounding;
  if (moving > 0) metrics->bow_direction_accuracy = static_cast<double>(direction_right) / moving;
  if (sp_count > 0) metrics->sounding_point_error_mm = sp_sum / sp_count;
}

void ScoreDoubleStops(const std::vector<FrameVoices>& truth,
                      const std::vector<FrameVoices>* method,
                      MethodMetrics* metrics) {
  if (method && method->size() != truth.size()) {
    throw std::invalid_argument("double stops: " + std::to_string(method->size()) +
                                " frames but the truth has " + std::to_string(truth.size()));
  }
  int frames = 0, string_hits = 0, finger_hits = 0, false_frames = 0;
  for (size_t f = 0; f < truth.size(); ++f) {
    const FrameVoices& t = truth[f];
    if (!t.DoubleStop()) {
      false_frames += method && (*method)[f].DoubleStop();
      continue;
    }
    ++frames;
    if (!method) continue;
    const FrameVoices& m = (*method)[f];
    if (!m.DoubleStop()) continue;
    const bool same = m.string[0] == t.string[0] && m.string[1] == t.string[1];
    const bool swapped = m.string[0] == t.string[1] && m.string[1] == t.string[0];
    string_hits += same || swapped;
    finger_hits += (same && m.finger[0] == t.finger[0] && m.finger[1] == t.finger[1]) ||
                   (swapped && m.finger[0] == t.finger[1] && m.finger[1] == t.finger[0]);
  }
  metrics->double_stop_truth = frames > 0;
  metrics->double_stop_frames = frames;
  if (method) metrics->false_double_stop_frames = false_frames;
  if (method && frames > 0) {
    metrics->double_stop_string_accuracy = static_cast<double>(string_hits) / frames;
    metrics->double_stop_finger_accuracy = static_cast<double>(finger_hits) / frames;
  }
}

}  // namespace arco::eval
