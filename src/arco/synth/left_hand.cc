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

hand::HandPose FingerPose(const hand::HandModel& model, double mcp, double pip, double dip) {
  using hand::FingerDof;
  hand::HandPose pose;
  for (int f = 1; f < 5; ++f) {
    const auto finger = static_cast<hand::Finger>(f);
    pose.angle_rad(finger, FingerDof::kBaseFlex) = mcp * kDeg;
    pose.angle_rad(finger, FingerDof::kMiddleFlex) = pip * kDeg;
    pose.angle_rad(finger, FingerDof::kDistalFlex) = dip * kDeg;
  }
  pose.angle_rad(hand::Finger::kThumb, FingerDof::kBaseFlex) = 20 * kDeg;
  pose.angle_rad(hand::Finger::kThumb, FingerDof::kBaseAbd) = 30 * kDeg;
  pose.angle_rad(hand::Finger::kThumb, FingerDof::kMiddleFlex) = 15 * kDeg;
  pose.angle_rad(hand::Finger::kThumb, FingerDof::kDistalFlex) = 15 * kDeg;
  return hand::ClampToLimits(model, pose);
}

}  // namespace

Status LeftHandOptions::Validate() const {
  for (double v : {relax_s, shift_s, change_s, hover_mm}) {
    if (!(v >= 0) || !std::isfinite(v)) {
      return Status::Error("left hand: distances and durations must be finite and >= 0");
    }
  }
  for (double v : {press_mcp_deg, press_pip_deg, press_dip_deg}) {
    if (!(v >= -30 && v <= 120))
      return Status::Error("left hand: pressing angles must be in [-30, 120] deg");
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
  press_pose_ =
      FingerPose(model, options.press_mcp_deg, options.press_pip_deg, options.press_dip_deg);
  curl_pose_ = FingerPose(model, 35, 55, 20);
  const hand::HandPointsMm in_wrist = hand::ForwardKinematicsInWrist(model, press_pose_);
  tip_from_mcp_.resize(5);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int f = 0; f < 5; ++f) {
    tip_from_mcp_[f] =
        wrist_rotation_ *
        (in_wrist[hand::TipKeypoint(static_cast<hand::Finger>(f))] - middle_mcp_in_wrist_);
    if (f > 0) mean += tip_from_mcp_[f] / 4;
  }
  // Anchors per note and the glide into each note.
  int max_offset = 0;
  for (const FingerSpan& s : GetInstrumentInfo(instrument.kind()).hand_frame) {
    if (!s.extended) max_offset = std::max(max_offset, s.offset_semitones);
  }
  const int n = instrument.num_strings();
  const auto& notes = performance.notes;
  for (size_t i = 0; i < notes.size(); ++i) {
    const PerformedNote& note = notes[i];
    const int string = n - note.fingering.string_index;
    Eigen::Vector3d anchor;
    if (note.fingering.IsDoubleStop() && note.fingering.second_finger > 0) {
      const int f1 = note.fingering.finger, f2 = note.fingering.second_finger;
      const Eigen::Vector3d c2 = ContactInInstrument(
          instrument,
          tmpl,
          string - 1,
          MidiToHz(note.note.second_midi_note + note.second_intonation_cents / 100.0,
                   performance.a4_hz));
      if (f1 == 0) {
        anchor = c2 - tip_from_mcp_[f2];
      } else {
        const Eigen::Vector3d c1 = ContactInInstrument(
            instrument,
            tmpl,
            string,
            MidiToHz(note.note.midi_note + note.intonation_cents / 100.0, performance.a4_hz));
        anchor = f1 == f2
                     ? Eigen::Vector3d(0.5 * (c1 + c2) - tip_from_mcp_[f1])
                     : Eigen::Vector3d(0.5 * ((c1 - tip_from_mcp_[f1]) + (c2 - tip_from_mcp_[f2])));
      }
    } else if (note.fingering.finger > 0) {
      const double centre_hz =
          MidiToHz(note.note.midi_note + note.intonation_cents / 100.0, performance.a4_hz);
      anchor = ContactInInstrument(instrument, tmpl, string, centre_hz) -
               tip_from_mcp_[note.fingering.finger];
    } else {
      const double x = PlaceX(note.fingering.position_semitones + 0.5 * max_offset);
      anchor = Eigen::Vector3d(x, StringY(string, x), 0) - mean;
    }
    anchors_.push_back(anchor);
    double glide = options.change_s;
    if (i > 0) {
      if (note.fingering.position_semitones != notes[i - 1].fingering.position_semitones)
        glide = options.shift_s;
      glide = std::min(glide, 0.5 * (note.note.onset_s - notes[i - 1].note.onset_s));
    }
    glide_s_.push_back(glide);
  }
  // A rolled chord's two pairs (ScoreNote::chord_upper_pair): the hand holds all the chord's
  // fingers from its start, so it stays put between the pairs, midway between where each
  // pair alone would put it.
  for (size_t i = 1; i < notes.size(); ++i) {
    if (!notes[i].note.chord_upper_pair) continue;
    const Eigen::Vector3d held = 0.5 * (anchors_[i - 1] + anchors_[i]);
    anchors_[i - 1] = held;
    anchors_[i] = held;
  }
}

double LeftHandAnimator::PlaceX(double semitones) const {
  return instrument_.string_length_mm() * std::pow(2.0, -semitones / 12.0);
}

double LeftHandAnimator::StringY(int string, double x) const {
  const StringSegment& s = tmpl_.strings_mm[static_cast<size_t>(string - 1)];
  const double f = std::clamp(x / instrument_.string_length_mm(), 0.0, 1.0);
  return s.PointAtFraction(f).y();
}

Eigen::Vector3d LeftHandAnimator::AnchorAt(double t) const {
  const auto& notes = perf_.notes;
  // Next note to start after t.
  size_t next = 0;
  while (next < notes.size() && notes[next].note.onset_s <= t) ++next;
  if (next == 0) return anchors_.front();
  if (next == notes.size()) return anchors_.back();
  // A pressing finger holds the hand until its note ends; after an open string
  // the hand is free to travel during the end of the note.
  const PerformedNote& prev = notes[next - 1];
  double start = notes[next].note.onset_s - glide_s_[next];
  if (prev.fingering.finger > 0) start = std::max(start, prev.note.offset_s);
  const double glide = notes[next].note.onset_s - start;
  if (t <= start || glide <= 0) return anchors_[next - 1];
  return anchors_[next - 1] +
         (anchors_[next] - anchors_[next - 1]) * SmoothStep((t - start) / glide);
}

LeftHandFrame LeftHandAnimator::Next(double t) {
  if (t < last_time_s_) throw std::invalid_argument("LeftHandAnimator: time went backwards");
  last_time_s_ = t;
  LeftHandFrame out;
  out.note_index = perf_.NoteIndexAt(t);
  out.f0_hz = perf_.F0HzAt(t);
  const int n = instrument_.num_strings();
  const auto& notes = perf_.notes;
  // The note whose hand shape we hold: the sounding one, else the next, else the last.
  int held = out.note_index;
  if (held < 0) {
    held = static_cast<int>(notes.size()) - 1;
    for (size_t i = 0; i < notes.size(); ++i) {
      if (notes[i].note.onset_s > t) {
        held = static_cast<int>(i);
        break;
      }
    }
  }
  const PerformedNote& hn = notes[static_cast<size_t>(held)];
  const bool pressed = out.note_index >= 0 && hn.fingering.finger > 0;
  const int hand_string = n - hn.fingering.string_index;

  Eigen::Vector3d anchor = AnchorAt(t);
  Eigen::Vector3d contact = Eigen::Vector3d::Constant(NAN);
  // The double stop's upper note: its own string's contact; the hand rocks with it when
  // the lower note is open.
  const bool second_pressed =
      out.note_index >= 0 && hn.fingering.IsDoubleStop() && hn.fingering.second_finger > 0;
  if (out.note_index >= 0 && hn.fingering.IsDoubleStop()) {
    out.double_stop = true;
    out.second_string = hand_string - 1;
    out.second_f0_hz = perf_.SecondF0HzAt(t);
    out.second_open = hn.fingering.second_finger == 0;
    if (second_pressed) {
      out.second_finger = hn.fingering.second_finger;
      out.second_contact_mm =
          ContactInInstrument(instrument_, tmpl_, out.second_string, out.second_f0_hz);
      if (!pressed && options_.rock_with_vibrato) {
        const double centre_hz =
            MidiToHz(hn.note.second_midi_note + hn.second_intonation_cents / 100.0, perf_.a4_hz);
        anchor += out.second_contact_mm -
                  ContactInInstrument(instrument_, tmpl_, out.second_string, centre_hz);
      }
    }
  }
  if (pressed) {
    contact = ContactInInstrument(instrument_, tmpl_, hand_string, out.f0_hz);
    if (options_.rock_with_vibrato) {
      const double centre_hz =
          MidiToHz(hn.note.midi_note + hn.intonation_cents / 100.0, perf_.a4_hz);
      anchor += contact - ContactInInstrument(instrument_, tmpl_, hand_string, centre_hz);
    }
    out.string = hand_string;
    out.finger = hn.fingering.finger;
    out.contact_mm = contact;
  }
  hand::HandPose pose = previous_ ? *previous_ : press_pose_;
  pose.world_from_wrist.rotation = wrist_rotation_;
  pose.world_from_wrist.translation = anchor - wrist_rotation_ * middle_mcp_in_wrist_;

  // Idle fingers (and the thumb behind the neck) relax towards a hovering curl
  // with a time constant of relax_s, so a finger that stops pressing lifts off
  // smoothly instead of jumping.
  const double dt = previous_ ? t - previous_time_s_ : 1e9;
  const double keep = options_.relax_s > 0 ? std::exp(-dt / options_.relax_s) : 0.0;
  for (int f = 0; f < 5; ++f) {
    if (pressed && f == hn.fingering.finger) continue;
    if (second_pressed && f == hn.fingering.second_finger) continue;
    for (int d = 0; d < 4; ++d) {
      const int k = 4 * f + d;
      pose.angles_rad[k] =
          curl_pose_.angles_rad[k] + keep * (pose.angles_rad[k] - curl_pose_.angles_rad[k]);
    }
  }
  if (options_.ik_idle_fingers) {
    hand::FingerIkOptions hover;
    hover.joints = hand::FingerIkJoints::kAll;
    hover.exact_reach = false;
    hover.seed_levels = 0;
    hover.max_iterations = 25;
    const int position = hn.fingering.position_semitones;
    for (const FingerSpan& span : GetInstrumentInfo(instrument_.kind()).hand_frame) {
      if (span.extended || (pressed && span.finger == hn.fingering.finger)) continue;
      const double x = PlaceX(position + span.offset_semitones);
      const Eigen::Vector3d target(x, StringY(hand_string, x), options_.hover_mm);
      pose = hand::SolveFingertipIk(
                 model_, pose, static_cast<hand::Finger>(span.finger), target, hover)
                 .pose;
    }
  }
  hand::FingerIkOptions press;
  press.joints = hand::FingerIkJoints::kAll;
  press.exact_reach = true;
  press.seed_levels = 0;
  press.max_iterations = 50;
  if (previous_) {
    press.previous_pose = previous_;
    press.previous_weight_mm_per_rad = 5.0;
  }
  // One finger to its target by IK from the pressing posture; returns what it misses by.
  auto place = [&](int finger_index, const Eigen::Vector3d& target) {
    const auto finger = static_cast<hand::Finger>(finger_index);
    hand::HandPose ref = pose;
    for (int d = 0; d < 4; ++d) {
      ref.angles_rad[4 * finger_index + d] = press_pose_.angles_rad[4 * finger_index + d];
    }
    pose = hand::SolveFingertipIk(model_, ref, finger, target, press).pose;
    return Eigen::Vector3d(target - hand::FingertipInWorld(model_, pose, finger));
  };
  const bool fifth = pressed && second_pressed && hn.fingering.second_finger == hn.fingering.finger;
  Eigen::Vector3d target_first = contact;
  if (pressed) {
    // A fifth under one finger: its tip midway between the two strings' contacts.
    target_first = fifth ? Eigen::Vector3d(0.5 * (contact + out.second_contact_mm)) : contact;
    // Take up what the joints could not reach by moving the whole hand.
    const Eigen::Vector3d residual = place(hn.fingering.finger, target_first);
    out.residual_shift_mm = residual.norm();
    pose.world_from_wrist.translation += residual;
  }
  if (second_pressed && !fifth) {
    Eigen::Vector3d residual = place(hn.fingering.second_finger, out.second_contact_mm);
    if (pressed) {
      // Two fingers: the hand moves by the mean of what each misses, a few rounds, so the
      // two fingertips share the miss the joints cannot take up (the first was exact).
      Eigen::Vector3d first = Eigen::Vector3d::Zero();
      for (int round = 0; round < 6 && std::max(first.norm(), residual.norm()) > 0.5; ++round) {
        pose.world_from_wrist.translation += 0.5 * (first + residual);
        first = place(hn.fingering.finger, target_first);
        residual = place(hn.fingering.second_finger, out.second_contact_mm);
      }
      out.second_residual_mm = std::max(first.norm(), residual.norm());
    } else {
      out.residual_shift_mm = residual.norm();
      pose.world_from_wrist.translation += residual;
    }
  }
  // A rolled chord (ScoreNote::chord_upper_pair): from its lower pair's onset to its upper
  // pair's offset every finger of the chord stays down on its string at the note's centre
  // pitch, the sounding pair's as placed above, the others by IK alone (the hand is already
  // where the chord puts it).
  size_t chord_lower = notes.size();
  if (hn.note.chord_upper_pair && held > 0) {
    chord_lower = static_cast<size_t>(held) - 1;
  } else if (static_cast<size_t>(held) + 1 < notes.size() &&
             notes[static_cast<size_t>(held) + 1].note.chord_upper_pair) {
    chord_lower = static_cast<size_t>(held);
  }
  if (chord_lower < notes.size() && t >= notes[chord_lower].note.onset_s &&
      t <= notes[chord_lower + 1].note.offset_s) {
    for (size_t c = chord_lower; c <= chord_lower + 1; ++c) {
      const PerformedNote& pn = notes[c];
      const Eigen::Vector3d first = ContactInInstrument(
          instrument_,
          tmpl_,
          n - pn.fingering.string_index,
          MidiToHz(pn.note.midi_note + pn.intonation_cents / 100.0, perf_.a4_hz));
      const Eigen::Vector3d second = ContactInInstrument(
          instrument_,
          tmpl_,
          n - pn.fingering.second_string_index,
          MidiToHz(pn.note.second_midi_note + pn.second_intonation_cents / 100.0, perf_.a4_hz));
      const bool fifth = pn.fingering.finger == pn.fingering.second_finger;
      auto hold = [&](int finger, const Eigen::Vector3d& target) {
        // The sounding pair's fingers (and a 3-note chord's shared one) are already down.
        if (finger == 0 || finger == out.finger || finger == out.second_finger) return;
        place(finger, target);
      };
      hold(pn.fingering.finger, fifth ? Eigen::Vector3d(0.5 * (first + second)) : first);
      if (!fifth) hold(pn.fingering.second_finger, second);
    }
  }
  out.pose = pose;
  previous_ = pose;
  previous_time_s_ = t;
  return out;
}

}  // namespace arco::synth
