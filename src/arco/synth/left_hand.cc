#include "arco/synth/left_hand.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "arco/hand/ik.h"
#include "arco/hand/kinematics.h"
#include "arco/synth/fingering.h"

namespace arco::synth {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

double SmoothStep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3 - 2 * x);
}

// A relaxed playing curl, the IK's reference (clamped into the model's limits).
hand::HandPose CurledPose(const hand::HandModel& model) {
  using hand::FingerDof;
  hand::HandPose pose;
  for (int f = 1; f < 5; ++f) {
    const auto finger = static_cast<hand::Finger>(f);
    pose.angle_rad(finger, FingerDof::kBaseFlex) = 35 * kDeg;
    pose.angle_rad(finger, FingerDof::kMiddleFlex) = 55 * kDeg;
    pose.angle_rad(finger, FingerDof::kDistalFlex) = 20 * kDeg;
  }
  pose.angle_rad(hand::Finger::kThumb, FingerDof::kBaseFlex) = 20 * kDeg;
  pose.angle_rad(hand::Finger::kThumb, FingerDof::kBaseAbd) = 30 * kDeg;
  pose.angle_rad(hand::Finger::kThumb, FingerDof::kMiddleFlex) = 15 * kDeg;
  pose.angle_rad(hand::Finger::kThumb, FingerDof::kDistalFlex) = 15 * kDeg;
  return hand::ClampToLimits(model, pose);
}

}  // namespace

Status LeftHandOptions::Validate() const {
  for (double v : {hover_mm, mcp_beside_string_mm, mcp_above_strings_mm, shift_s, string_change_s}) {
    if (!(v >= 0) || !std::isfinite(v)) {
      return Status::Error("left hand: distances and durations must be finite and >= 0");
    }
  }
  return Status::Ok();
}

LeftHandAnimator::LeftHandAnimator(const hand::HandModel& model,
                                   const InstrumentModel& instrument,
                                   const InstrumentTemplate& tmpl,
                                   const Performance& performance,
                                   const LeftHandOptions& options)
    : model_(model), instrument_(instrument), tmpl_(tmpl), perf_(performance), options_(options) {
  const Status status = options.Validate();
  if (!status.ok()) throw std::invalid_argument(status.message());
  if (model.side() != hand::HandSide::kLeft) {
    throw std::invalid_argument("LeftHandAnimator needs a left hand model");
  }
  // Wrist frame in the instrument frame: index side (-x of a left hand) towards
  // the nut (+x), fingers pointing forward over the fingerboard and a little
  // towards the low strings, palm facing the low-string side.
  const Eigen::Vector3d x_hand(-1, 0, 0);
  const Eigen::Vector3d y_hand = Eigen::Vector3d(0, 0.35, 0.94).normalized();
  wrist_rotation_.col(0) = x_hand;
  wrist_rotation_.col(1) = y_hand;
  wrist_rotation_.col(2) = x_hand.cross(y_hand);
  middle_mcp_in_wrist_ = model.rest_point_mm(hand::KeypointIndex(hand::Finger::kMiddle, 0));
}

double LeftHandAnimator::AnchorX(double position_semitones) const {
  // Middle of the four finger places of this position.
  int max_offset = 0;
  for (const FingerSpan& s : HandFrameFor(instrument_.name())) {
    if (!s.extended) max_offset = std::max(max_offset, s.offset_semitones);
  }
  return instrument_.string_length_mm() *
         std::pow(2.0, -(position_semitones + 0.5 * max_offset) / 12.0);
}

double LeftHandAnimator::StringY(int string, double x) const {
  const StringSegment& s = tmpl_.strings_mm[static_cast<size_t>(string - 1)];
  const double f = std::clamp(x / instrument_.string_length_mm(), 0.0, 1.0);
  return s.PointAtFraction(f).y();
}

double LeftHandAnimator::PositionAt(double t) const {
  const auto& notes = perf_.notes;
  if (notes.empty()) return 2;
  // Last note that started at or before t (or the first note).
  size_t i = 0;
  while (i + 1 < notes.size() && notes[i + 1].note.onset_s <= t) ++i;
  double p = notes[i].fingering.position_semitones;
  if (t < notes[0].note.onset_s) return notes[0].fingering.position_semitones;
  if (i + 1 < notes.size()) {
    const PerformedNote& next = notes[i + 1];
    const double q = next.fingering.position_semitones;
    if (q != p) {
      const double start = std::max(next.note.onset_s - options_.shift_s,
                                    0.5 * (notes[i].note.onset_s + next.note.onset_s));
      const double dur = next.note.onset_s - start;
      if (t > start && dur > 0) p += (q - p) * SmoothStep((t - start) / dur);
    }
  }
  return p;
}

int LeftHandAnimator::StringForHandAt(double t) const {
  // The string of the sounding note, else of the next note, else of the last.
  const int n = static_cast<int>(instrument_.num_strings());
  const auto& notes = perf_.notes;
  for (const PerformedNote& note : notes) {
    if (note.note.offset_s > t) return n - note.fingering.string_index;
  }
  return notes.empty() ? 1 : n - notes.back().fingering.string_index;
}

LeftHandFrame LeftHandAnimator::Next(double t) {
  if (t < last_time_s_) throw std::invalid_argument("LeftHandAnimator: time went backwards");
  const double frame_dt = std::isfinite(last_time_s_) && last_time_s_ > -1e299 ? t - last_time_s_ : 0;
  last_time_s_ = t;
  LeftHandFrame out;
  out.note_index = perf_.NoteIndexAt(t);
  out.f0_hz = perf_.F0HzAt(t);
  const int n = instrument_.num_strings();
  const PerformedNote* note = out.note_index >= 0 ? &perf_.notes[static_cast<size_t>(out.note_index)] : nullptr;
  const bool pressed = note && note->fingering.finger > 0;

  // 1. Anchor of the middle MCP.
  const double p = PositionAt(t);
  const int hand_string = pressed ? n - note->fingering.string_index : StringForHandAt(t);
  double x_anchor = AnchorX(p);
  const double target_y = StringY(hand_string, x_anchor);
  if (std::isnan(smoothed_string_y_) || options_.string_change_s <= 0) {
    smoothed_string_y_ = target_y;
  } else {
    // First-order glide towards the played string (time constant string_change_s / 3).
    const double a = 1 - std::exp(-3 * frame_dt / options_.string_change_s);
    smoothed_string_y_ += a * (target_y - smoothed_string_y_);
  }
  // 2. Vibrato: rock along the string with the contact point.
  Eigen::Vector3d contact = Eigen::Vector3d::Constant(NAN);
  if (pressed) {
    const int string = n - note->fingering.string_index;
    contact = ContactInInstrument(instrument_, tmpl_, string, out.f0_hz);
    if (options_.rock_with_vibrato) {
      const double centre_hz = MidiToHz(note->note.midi_note + note->intonation_cents / 100.0, perf_.a4_hz);
      const Eigen::Vector3d centre = ContactInInstrument(instrument_, tmpl_, string, centre_hz);
      x_anchor += contact.x() - centre.x();
    }
    out.string = string;
    out.finger = note->fingering.finger;
    out.contact_mm = contact;
  }
  const Eigen::Vector3d mcp_target(x_anchor, smoothed_string_y_ - options_.mcp_beside_string_mm,
                                   options_.mcp_above_strings_mm);
  hand::HandPose pose = previous_ ? *previous_ : CurledPose(model_);
  pose.world_from_wrist_rotation = wrist_rotation_;
  pose.wrist_in_world_mm = mcp_target - wrist_rotation_ * middle_mcp_in_wrist_;

  // 3. Fingers. Idle fingers hover over their own places on the hand's string.
  hand::FingerIkOptions hover;
  hover.joints = hand::FingerIkJoints::kAll;
  hover.exact_reach = false;
  hover.seed_levels = 0;
  hover.max_iterations = 30;
  if (previous_) {
    hover.previous_pose = previous_;
    hover.previous_weight_mm_per_rad = 5.0;
  }
  const hand::HandPose curl = CurledPose(model_);
  const int position = static_cast<int>(std::lround(p));
  for (const FingerSpan& span : HandFrameFor(instrument_.name())) {
    if (span.extended) continue;
    if (pressed && span.finger == note->fingering.finger) continue;
    const double semis = position + span.offset_semitones;
    const double x = instrument_.string_length_mm() * std::pow(2.0, -semis / 12.0);
    const Eigen::Vector3d target(x, StringY(hand_string, x), options_.hover_mm);
    // Keep the reference curl for this finger, the rest of the pose as solved so far.
    hand::HandPose ref = pose;
    for (int d = 0; d < 4; ++d) {
      ref.angles_rad[4 * span.finger + d] = curl.angles_rad[4 * span.finger + d];
    }
    pose = hand::SolveFingertipIk(model_, ref, static_cast<hand::Finger>(span.finger), target, hover).pose;
  }
  // The thumb behind the neck, under the second finger's place.
  {
    const double x = AnchorX(p);
    const Eigen::Vector3d target(x, -0.25 * tmpl_.neck_depth_mm, -tmpl_.neck_depth_mm);
    pose = hand::SolveFingertipIk(model_, pose, hand::Finger::kThumb, target, hover).pose;
  }
  if (pressed) {
    hand::FingerIkOptions press = hover;
    press.exact_reach = true;
    press.seed_levels = 2;
    press.max_iterations = 100;
    const auto finger = static_cast<hand::Finger>(note->fingering.finger);
    pose = hand::SolveFingertipIk(model_, pose, finger, contact, press).pose;
    // Take up what the joints could not reach by moving the whole hand.
    const Eigen::Vector3d residual = contact - hand::FingertipInWorld(model_, pose, finger);
    out.residual_shift_mm = residual.norm();
    pose.wrist_in_world_mm += residual;
  }
  out.pose = pose;
  previous_ = pose;
  return out;
}

}  // namespace arco::synth
