#include "arco/synth/bow.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "arco/hand/kinematics.h"

namespace arco::synth {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

double SmoothStep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3 - 2 * x);
}

double TypicalBowMm(InstrumentKind kind) {
  switch (kind) {
    case InstrumentKind::kViolin:
      return 600;
    case InstrumentKind::kViola:
      return 610;
    case InstrumentKind::kCello:
      return 641;  // frog-tip distance of the real SPD labels (DOMAIN.md section 5)
    case InstrumentKind::kDoubleBass:
      return 580;
  }
  return 641;
}

}  // namespace

Status BowOptions::Validate() const {
  if (!(bow_length_mm >= 0) || !std::isfinite(bow_length_mm)) {
    return Status::Error("bow: length must be >= 0 (0 = typical)");
  }
  if (!(contact_fraction > 0 && contact_fraction < 0.3)) {
    return Status::Error("bow: contact fraction must be in (0, 0.3)");
  }
  if (!(crossing_s >= 0) || !(lift_mm >= 0)) {
    return Status::Error("bow: crossing_s and lift_mm must be >= 0");
  }
  return Status::Ok();
}

BowAnimator::BowAnimator(const hand::HandModel& right_hand,
                         const InstrumentModel& instrument,
                         const InstrumentTemplate& tmpl,
                         const Performance& performance,
                         const Eigen::Vector3d& right_side,
                         const BowOptions& options)
    : right_hand_(right_hand),
      instrument_(instrument),
      tmpl_(tmpl),
      perf_(performance),
      options_(options) {
  const Status status = options.Validate();
  if (!status.ok()) throw std::invalid_argument(status.message());
  bow_length_mm_ =
      options.bow_length_mm > 0 ? options.bow_length_mm : TypicalBowMm(instrument.kind());
  side_sign_ = right_side.y() >= 0 ? 1.0 : -1.0;
  // Strokes: alternate down/up; the bow used grows with the note's length.
  double s = 0.15;
  bool down = true;
  for (const PerformedNote& n : performance.notes) {
    const double dur = n.note.offset_s - n.note.onset_s;
    const double used = std::min(0.7, 0.15 + 0.3 * dur);
    double e = down ? s + used : s - used;
    if (e > 0.9) e = 0.9;
    if (e < 0.1) e = 0.1;
    stroke_start_.push_back(s);
    stroke_end_.push_back(e);
    s = e;
    down = !down;
  }
  // Bow hold: fingers draped over the stick, thumb bent under the frog.
  using hand::Finger;
  using hand::FingerDof;
  for (int f = 1; f < 5; ++f) {
    hold_.angle_rad(static_cast<Finger>(f), FingerDof::kBaseFlex) = (40 + 5 * f) * kDeg;
    hold_.angle_rad(static_cast<Finger>(f), FingerDof::kMiddleFlex) = 60 * kDeg;
    hold_.angle_rad(static_cast<Finger>(f), FingerDof::kDistalFlex) = 25 * kDeg;
  }
  hold_.angle_rad(Finger::kThumb, FingerDof::kBaseFlex) = 30 * kDeg;
  hold_.angle_rad(Finger::kThumb, FingerDof::kBaseAbd) = 35 * kDeg;
  hold_.angle_rad(Finger::kThumb, FingerDof::kMiddleFlex) = 30 * kDeg;
  hold_.angle_rad(Finger::kThumb, FingerDof::kDistalFlex) = 30 * kDeg;
  hold_ = hand::ClampToLimits(right_hand, hold_);
}

double BowAnimator::TiltRad(int string) const {
  // The bow direction u = (0, -side cos t, sin t) has the inclination atan(u_z / u_y) =
  // BowInclinationRad(string) when t = -side * that inclination.
  return -side_sign_ * instrument_.BowInclinationRad(string);
}

double BowAnimator::ContactFraction(size_t note) const {
  const double v = std::clamp(perf_.notes[note].note.velocity, 1, 127);
  return options_.contact_fraction * (1.25 - 0.5 * (v - 1) / 126.0);
}

double BowAnimator::BowFractionAt(double t) const {
  const auto& notes = perf_.notes;
  double s = 0.15;
  for (size_t i = 0; i < notes.size(); ++i) {
    const auto& n = notes[i].note;
    if (t < n.onset_s) return s;  // silence before note i: bow waits
    if (t < n.offset_s) {
      const double u = (t - n.onset_s) / (n.offset_s - n.onset_s);
      return stroke_start_[i] + (stroke_end_[i] - stroke_start_[i]) * u;
    }
    s = stroke_end_[i];
  }
  return s;
}

BowAnimator::Rest BowAnimator::RestOn(size_t note) const {
  const int n_strings = instrument_.num_strings();
  const NoteFingering& fingering = perf_.notes[note].fingering;
  Rest rest;
  rest.string = n_strings - fingering.string_index;
  rest.tilt_rad = TiltRad(rest.string);
  if (fingering.IsDoubleStop()) {
    // A double stop is bowed on both strings at once: the bow line is the chord through
    // the two strings' tops on the bridge's arch, whose inclination is the mean of the
    // two tangents' (refine/bowing.h reads it back as a double stop), and it crosses the
    // strings' plane between them.
    rest.second_string = n_strings - fingering.second_string_index;
    rest.tilt_rad = 0.5 * (rest.tilt_rad + TiltRad(rest.second_string));
  }
  return rest;
}

Eigen::Vector3d BowAnimator::ContactOn(const Rest& rest, double fraction) const {
  const Eigen::Vector3d c =
      tmpl_.strings_mm[static_cast<size_t>(rest.string - 1)].PointAtFraction(fraction);
  if (rest.second_string == 0) return c;
  return 0.5 * (c + tmpl_.strings_mm[static_cast<size_t>(rest.second_string - 1)].PointAtFraction(
                        fraction));
}

BowFrame BowAnimator::At(double t) const {
  BowFrame out;
  const auto& notes = perf_.notes;
  // String: the sounding note's, else the next note's, else the last.
  int idx = perf_.NoteIndexAt(t);
  double crossing_u = 1;
  size_t next = 0;
  while (next < notes.size() && notes[next].note.onset_s <= t) ++next;
  const size_t cur =
      idx >= 0 ? static_cast<size_t>(idx) : (next < notes.size() ? next : notes.size() - 1);
  const Rest rest = RestOn(cur);
  Rest prev_rest = cur > 0 ? RestOn(cur - 1) : rest;
  if (idx < 0 && next < notes.size()) {
    // In a gap before note `next`: cross towards its string as it approaches.
    prev_rest = next > 0 ? RestOn(next - 1) : rest;
    const double start = notes[next].note.onset_s - options_.crossing_s;
    crossing_u = options_.crossing_s > 0 ? SmoothStep((t - start) / options_.crossing_s) : 1;
  } else if (idx >= 0 && options_.crossing_s > 0) {
    crossing_u =
        SmoothStep((t - notes[cur].note.onset_s + options_.crossing_s) / options_.crossing_s);
  }
  const int string = rest.string;
  const double tilt = prev_rest.tilt_rad + (rest.tilt_rad - prev_rest.tilt_rad) * crossing_u;
  out.string = idx >= 0 ? string : 0;
  out.second_string = idx >= 0 ? rest.second_string : 0;
  const double lift = idx >= 0 ? 0.0 : options_.lift_mm;

  // Contact on the string (interpolated across strings while crossing).
  const double f = ContactFraction(cur);
  const Eigen::Vector3d c0 = ContactOn(prev_rest, f);
  const Eigen::Vector3d c1 = ContactOn(rest, f);
  if (idx >= 0) {
    const StringSegment& sounding = tmpl_.strings_mm[static_cast<size_t>(string - 1)];
    out.sounding_point_mm = f * (sounding.nut - sounding.bridge).norm();
    out.direction = stroke_end_[cur] >= stroke_start_[cur] ? 1 : -1;
  }
  const Eigen::Vector3d contact = c0 + (c1 - c0) * crossing_u + Eigen::Vector3d(0, 0, lift);
  // Bow direction frog -> tip: away from the performer's right, tilted about x.
  const Eigen::Vector3d u =
      (Eigen::Vector3d(0, -side_sign_ * std::cos(tilt), std::sin(tilt))).normalized();
  const double s = BowFractionAt(t);
  out.bow_position = s;
  out.frog_mm = contact - s * bow_length_mm_ * u;
  out.tip_mm = contact + (1 - s) * bow_length_mm_ * u;

  // Right hand: palm facing the stick, fingers draped over it towards the bridge
  // side, the middle knuckle just beyond the frog.
  const Eigen::Vector3d up = Eigen::Vector3d::UnitX().cross(u).dot(Eigen::Vector3d::UnitZ()) >= 0
                                 ? Eigen::Vector3d(Eigen::Vector3d::UnitX().cross(u))
                                 : Eigen::Vector3d(-Eigen::Vector3d::UnitX().cross(u));
  Eigen::Vector3d y_hand = (-0.75 * up - 0.55 * Eigen::Vector3d::UnitX() + 0.35 * u).normalized();
  Eigen::Vector3d z_hand = -up - (-up).dot(y_hand) * y_hand;  // palm towards the stick
  z_hand.normalize();
  Eigen::Matrix3d r;
  r.col(1) = y_hand;
  r.col(2) = z_hand;
  r.col(0) = y_hand.cross(z_hand);
  out.right_hand = hold_;
  out.right_hand.world_from_wrist.rotation = r;
  const Eigen::Vector3d mcp = out.frog_mm + 35 * up + 25 * u;
  out.right_hand.world_from_wrist.translation =
      mcp - r * right_hand_.rest_point_mm(hand::KeypointIndex(hand::Finger::kMiddle, 0));
  return out;
}

}  // namespace arco::synth
