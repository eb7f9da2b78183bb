#include "arco/refine/double_stop_refine.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "arco/hand/ik.h"
#include "arco/hand/kinematics.h"
#include "arco/instrument/contact.h"

namespace arco::refine {
namespace {

// Semitones of f0_hz above the open pitch of `string`.
double SemitonesAboveOpen(const InstrumentModel& model, int string, double f0_hz) {
  return 12.0 * std::log2(f0_hz / model.open_hz(string));
}

}  // namespace

Status DoubleStopRefineOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(
      CheckInRange("open_tolerance_cents", open_tolerance_cents, kOpenToleranceRangeCents));
  ARCO_RETURN_IF_ERROR(CheckInRange("max_span_semitones", max_span_semitones, kSpanRangeSemitones));
  ARCO_RETURN_IF_ERROR(CheckInRange("fifth_semitones", fifth_semitones, kSpanRangeSemitones));
  ARCO_RETURN_IF_ERROR(
      CheckInRange("max_tip_distance_mm", max_tip_distance_mm, kTipDistanceRangeMm));
  if (max_iterations < 1 || max_iterations > 1000)
    return Status::Error("max_iterations must be in [1, 1000]");
  return Status::Ok();
}

DoubleStopRefineResult RefineSecondVoice(const RefineInput& input,
                                         const RefineResult& first,
                                         const std::vector<double>& upper_f0_hz,
                                         const DoubleStopRefineOptions& options) {
  const Status status = options.Validate();
  if (!status.ok()) throw std::invalid_argument("RefineSecondVoice: " + status.message());
  const size_t frames = input.pitch.size();
  if (first.contacts.size() != frames || first.hand.size() != frames ||
      upper_f0_hz.size() != frames || input.strings_in_world_mm.size() != frames) {
    throw std::invalid_argument("RefineSecondVoice: per-frame inputs differ in length");
  }
  const InstrumentModel& model = *input.instrument;
  const hand::HandModel& hand_model = input.hand_model;
  DoubleStopRefineResult out;
  out.second.assign(frames, FrameContact{});
  out.hand = first.hand;
  hand::FingerIkOptions ik;
  ik.joints = hand::FingerIkJoints::kAll;
  ik.exact_reach = false;
  ik.seed_levels = 0;
  ik.restarts = 0;
  ik.max_iterations = options.max_iterations;
  // A note of the first voice whose frames mostly have an upper note keeps it on the rest
  // of its frames (the polyphonic tracker's window holds two notes only well inside a
  // double stop): its median upper f0, where that lies above the frame's own pitch.
  std::map<int, std::vector<double>> note_upper;
  std::map<int, int> note_frames;
  for (size_t f = 0; f < frames; ++f) {
    const int note = first.contacts[f].note;
    if (note < 0) continue;
    ++note_frames[note];
    if (upper_f0_hz[f] > 0) note_upper[note].push_back(upper_f0_hz[f]);
  }
  std::map<int, double> note_median;
  for (auto& [note, values] : note_upper) {
    if (2 * static_cast<int>(values.size()) < note_frames[note]) continue;
    std::sort(values.begin(), values.end());
    note_median[note] = values[values.size() / 2];
  }
  for (size_t f = 0; f < frames; ++f) {
    const FrameContact& c1 = first.contacts[f];
    double upper = upper_f0_hz[f];
    if (!(upper > 0) && options.fill_notes) {
      const auto it = note_median.find(c1.note);
      if (it != note_median.end() && it->second > 1.03 * c1.f0_hz) upper = it->second;
    }
    const bool sounding =
        c1.state == ContactState::kPressed || c1.state == ContactState::kOpenString;
    if (!(upper > 0) || !sounding || c1.string < 1) continue;
    ++out.summary.frames;
    FrameContact& c2 = out.second[f];
    c2.f0_hz = upper;
    c2.confidence = c1.confidence;
    c2.note = c1.note;
    c2.state = ContactState::kUncertain;
    c2.reason = ContactReason::kUnplayable;
    const int string = c1.string - 1;  // the next higher string
    if (string < 1) {
      ++out.summary.uncertain;
      continue;
    }
    const double above_open = SemitonesAboveOpen(model, string, upper);
    if (above_open < -options.open_tolerance_cents / 100.0) {
      ++out.summary.uncertain;
      continue;
    }
    c2.string = string;
    if (above_open <= options.open_tolerance_cents / 100.0) {
      c2.state = ContactState::kOpenString;
      c2.reason = ContactReason::kNone;
      ++out.summary.open_string;
      continue;
    }
    // The first voice's stop (0 for an open string) and the span between the two.
    const double first_stop =
        c1.state == ContactState::kPressed ? SemitonesAboveOpen(model, c1.string, c1.f0_hz) : 0.0;
    const std::vector<StringSegment>& strings = input.strings_in_world_mm[f];
    if (strings.empty()) {
      c2.reason = ContactReason::kNoInstrument;
      ++out.summary.uncertain;
      continue;
    }
    if (c1.state == ContactState::kPressed &&
        std::abs(above_open - first_stop) > options.max_span_semitones) {
      ++out.summary.uncertain;
      continue;
    }
    const Contact contact = ContactPoint(model, string, upper);
    if (!contact.stopped()) {
      ++out.summary.uncertain;
      continue;
    }
    const Eigen::Vector3d point =
        strings[static_cast<size_t>(string - 1)].PointAtFraction(contact.fraction_from_bridge);
    c2.point_in_world_mm = point;
    c2.from_nut_mm = model.string_length_mm() - contact.contact_from_bridge_mm;
    const std::optional<hand::HandPose>& pose = out.hand[f];
    if (!pose) {
      c2.reason = ContactReason::kNoHand;
      ++out.summary.uncertain;
      continue;
    }
    // The finger: the nearest fingertip, the first voice's own only for a fifth.
    const bool fifth = c1.state == ContactState::kPressed &&
                       std::abs(above_open - first_stop) <= options.fifth_semitones;
    int best = 0;
    double best_mm = 0;
    for (int finger = 1; finger <= 4; ++finger) {
      if (c1.state == ContactState::kPressed && finger == c1.finger && !fifth) continue;
      const double d =
          (hand::FingertipInWorld(hand_model, *pose, static_cast<hand::Finger>(finger)) - point)
              .norm();
      if (best == 0 || d < best_mm) best = finger, best_mm = d;
    }
    if (fifth) best = c1.finger, best_mm = c1.tip_distance_refined_mm;
    if (best == 0 || !(best_mm <= options.max_tip_distance_mm || fifth)) {
      c2.reason = ContactReason::kOutOfReach;
      ++out.summary.uncertain;
      continue;
    }
    c2.state = ContactState::kPressed;
    c2.reason = ContactReason::kNone;
    c2.finger = best;
    c2.tip_distance_vision_mm = best_mm;
    ++out.summary.pressed;
    if (fifth) {
      ++out.summary.one_finger_fifths;
      c2.tip_distance_refined_mm = c1.tip_distance_refined_mm;
      continue;
    }
    // The second finger to its contact, the first voice's finger untouched.
    const hand::FingerIkResult r =
        hand::SolveFingertipIk(hand_model, *pose, static_cast<hand::Finger>(best), point, ik);
    if (r.status.ok()) out.hand[f] = r.pose;
    c2.tip_distance_refined_mm =
        (hand::FingertipInWorld(hand_model, *out.hand[f], static_cast<hand::Finger>(best)) - point)
            .norm();
    out.summary.joint_limit_violations += hand::CountLimitViolations(hand_model, *out.hand[f]) > 0;
  }
  return out;
}

}  // namespace arco::refine
