#include "arco/refine/double_stop_refine.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "arco/hand/ik.h"
#include "arco/hand/kinematics.h"
#include "arco/instrument/contact.h"
#include "arco/util/stats.h"

namespace arco::refine {
namespace {

constexpr double kRadPerDeg = 3.14159265358979323846 / 180.0;
// Upper notes within half a semitone of each other are the same note (steps 0a, 0c).
bool SameUpper(double a_hz, double b_hz) { return std::abs(CentsBetween(b_hz, a_hz)) <= 50.0; }

// Semitones of f0_hz above the open pitch of `string`.
double SemitonesAboveOpen(const InstrumentModel& model, int string, double f0_hz) {
  return 12.0 * std::log2(f0_hz / model.open_hz(string));
}

double TipDistance(const hand::HandModel& model,
                   const hand::HandPose& pose,
                   int finger,
                   const Eigen::Vector3d& point) {
  return (hand::FingertipInWorld(model, pose, static_cast<hand::Finger>(finger)) - point).norm();
}

// Whether one frame of the hand (registry/instruments.h, FingerReaches: closed or
// extended) puts finger g1 at stop1 and finger g2 at stop2, each in semitones above its
// own open string: the two reaches give hand positions within half a semitone.
bool OneHandFrame(InstrumentKind kind, int g1, double stop1, int g2, double stop2) {
  for (const FingerSpan& a : FingerReaches(kind, g1)) {
    for (const FingerSpan& b : FingerReaches(kind, g2)) {
      if (std::abs((stop1 - a.offset_semitones) - (stop2 - b.offset_semitones)) <= 0.5) return true;
    }
  }
  return false;
}

// Each frame's two stops (semitones above their open strings); `stopped`: the second voice
// is stopped and waits for its finger.
struct Stop {
  bool stopped = false;
  double first = 0, second = 0;
  double interval = 0;  // semitones from the first voice's pitch up to the second's
};

// The fingers of one first-voice note's double-stop frames (`members`: one upper note). kOwn: each
// frame keeps the first voice's finger; kNearest: the fingertip nearest each frame's contact.
constexpr int kOwn = 0, kNearest = 0;
struct FingerPair {
  int first = kOwn, second = kNearest;
  bool fifth = false;  // one finger stops both strings
};

// A fifth (the stops within fifth_semitones) keeps the first voice's finger for both.
// Otherwise the pair of fingers one hand frame can hold (OneHandFrame, at the note's
// median stops) whose fingertips, as the cameras saw the hand, lie nearest both contacts
// over the note's frames: the first voice was decoded alone, and its finger may leave no
// finger of the same hand for the second stop (a sixth on the cello heard as fingers 1 and
// 4, two semitones apart where those fingers stand three apart). No such pair: the first
// voice's finger and the nearest other fingertip, frame by frame.
FingerPair ChooseFingers(const RefineInput& input,
                         const std::vector<FrameContact>& first,
                         const std::vector<FrameContact>& second,
                         const std::vector<std::optional<hand::HandPose>>& hands,
                         const std::vector<Stop>& stops,
                         const std::vector<size_t>& members,
                         bool may_change_first,
                         const DoubleStopRefineOptions& options) {
  std::vector<double> first_stops, second_stops, intervals;
  int pressed = 0;
  for (size_t f : members) {
    first_stops.push_back(stops[f].first);
    second_stops.push_back(stops[f].second);
    intervals.push_back(stops[f].interval);
    pressed += first[f].pressed();
  }
  // An octave's upper note is the lower note's 2nd partial as often as a second voice (a
  // single-note take under --double-stops hears many): it never moves the first voice.
  if (std::abs(UpperMedian(intervals) - 12.0) <= 0.5) may_change_first = false;
  const bool first_pressed = 2 * pressed > static_cast<int>(members.size());
  const double stop1 = UpperMedian(first_stops), stop2 = UpperMedian(second_stops);
  FingerPair pair;
  if (first_pressed && std::abs(stop1 - stop2) <= options.fifth_semitones) {
    pair.fifth = true;
    return pair;
  }
  // The first voice's own finger: its most frequent over the frames.
  std::array<int, 5> votes{};
  for (size_t f : members) {
    if (first[f].pressed()) ++votes[static_cast<size_t>(std::clamp(first[f].finger, 0, 4))];
  }
  const int own = static_cast<int>(std::max_element(votes.begin(), votes.end()) - votes.begin());
  const InstrumentKind kind = input.instrument->kind();
  double best_cost = std::numeric_limits<double>::infinity();
  for (int g1 = first_pressed ? 1 : 0; g1 <= (first_pressed ? 4 : 0); ++g1) {
    if (first_pressed && !may_change_first && g1 != own) continue;
    for (int g2 = 1; g2 <= 4; ++g2) {
      if (g2 == g1 || (g1 > 0 && !OneHandFrame(kind, g1, stop1, g2, stop2))) continue;
      double cost1 = 0, cost2 = 0;
      int count1 = 0;
      for (size_t f : members) {
        const std::optional<hand::HandPose>& seen =
            input.vision_hand[f] ? input.vision_hand[f] : hands[f];
        if (g1 > 0 && first[f].pressed()) {
          cost1 += TipDistance(input.hand_model, *seen, g1, first[f].point_in_world_mm);
          ++count1;
        }
        cost2 += TipDistance(input.hand_model, *seen, g2, second[f].point_in_world_mm);
      }
      // Both fingers within reach on average: a pair the hand does not show is no reason
      // to move the first voice (an upper "note" an octave up may be its own partial).
      const double reach = options.max_tip_distance_mm;
      if (cost2 > reach * static_cast<double>(members.size()) || cost1 > reach * count1) continue;
      if (cost1 + cost2 < best_cost) best_cost = cost1 + cost2, pair.first = g1, pair.second = g2;
    }
  }
  return pair;
}

// Moves the first voice of frame f to `string` at its own pitch (open within the
// tolerance, else stopped by the fingertip the cameras saw nearest the new contact, placed
// there by IK after the old finger went back to the cameras' pose). False, and nothing
// changed, where the string cannot give the pitch or there is no hand or no strings.
bool MoveFirstVoice(const RefineInput& input,
                    size_t f,
                    int string,
                    const hand::FingerIkOptions& ik,
                    const DoubleStopRefineOptions& options,
                    FrameContact* c1,
                    std::optional<hand::HandPose>* hand) {
  const InstrumentModel& model = *input.instrument;
  const double above_open = SemitonesAboveOpen(model, string, c1->f0_hz);
  if (above_open < -options.open_tolerance_cents / 100.0 || !*hand) return false;
  hand::HandPose pose = **hand;
  const std::optional<hand::HandPose>& vision = input.vision_hand[f];
  if (c1->pressed() && vision) {  // the old finger leaves its stop
    for (int d = 0; d < 4; ++d) {
      const int i =
          hand::DofIndex(static_cast<hand::Finger>(c1->finger), static_cast<hand::FingerDof>(d));
      pose.angles_rad[static_cast<size_t>(i)] = vision->angles_rad[static_cast<size_t>(i)];
    }
  }
  FrameContact moved = *c1;
  moved.string = string;
  moved.reason = ContactReason::kNone;
  if (above_open <= options.open_tolerance_cents / 100.0) {
    moved.state = ContactState::kOpenString;
    moved.finger = 0;
    moved.point_in_world_mm = Eigen::Vector3d::Constant(kNaN);
    moved.from_nut_mm = moved.tip_distance_vision_mm = moved.tip_distance_refined_mm = kNaN;
  } else {
    const std::vector<StringSegment>& strings = input.strings_in_world_mm[f];
    const Contact contact = ContactPoint(model, string, c1->f0_hz);
    if (strings.empty() || !contact.stopped()) return false;
    moved.state = ContactState::kPressed;
    moved.point_in_world_mm =
        strings[static_cast<size_t>(string - 1)].PointAtFraction(contact.fraction_from_bridge);
    moved.from_nut_mm = model.string_length_mm() - contact.contact_from_bridge_mm;
    const hand::HandPose& seen = vision ? *vision : **hand;
    double best_mm = std::numeric_limits<double>::infinity();
    for (int finger = 1; finger <= 4; ++finger) {
      const double d = TipDistance(input.hand_model, seen, finger, moved.point_in_world_mm);
      if (d < best_mm) best_mm = d, moved.finger = finger;
    }
    const hand::FingerIkResult r = hand::SolveFingertipIk(input.hand_model,
                                                          pose,
                                                          static_cast<hand::Finger>(moved.finger),
                                                          moved.point_in_world_mm,
                                                          ik);
    if (r.status.ok()) pose = r.pose;
    moved.tip_distance_vision_mm = best_mm;
    moved.tip_distance_refined_mm =
        TipDistance(input.hand_model, pose, moved.finger, moved.point_in_world_mm);
  }
  *c1 = moved;
  *hand = pose;
  return true;
}

// A rolled chord is two double stops in a row: a short lower pair, then the upper pair held.
// The two pairs share one hand, so the lower pair's strings follow the upper pair's: when
// the lower pair's upper note is the upper pair's lower note (a 3-note chord: one finger
// holds it on one string) the lower pair lies on the string below the upper pair's and the
// one it shares; when all four notes differ (a 4-note chord) on the two strings below the
// upper pair's. A lower pair is a double-stop note of at most chord_lower_max_s; its upper
// pair the next longer double-stop note, beginning at most chord_gap_s after it ends.
// Returns the first-voice frames moved to another string (MoveFirstVoice).
int TieChords(const RefineInput& input,
              const std::map<int, double>& note_upper_hz,
              const hand::FingerIkOptions& ik,
              const DoubleStopRefineOptions& options,
              DoubleStopRefineResult* out) {
  const InstrumentModel& model = *input.instrument;
  struct Span {
    int note = -1;
    size_t first = 0, last = 0;
    std::vector<double> f0_hz;    // the first voice's sounding frames
    std::array<int, 8> string{};  // votes of its sounding frames
  };
  std::map<int, Span> spans;
  for (size_t f = 0; f < out->first.size(); ++f) {
    const FrameContact& c = out->first[f];
    if (note_upper_hz.count(c.note) == 0) continue;
    auto [it, fresh] = spans.try_emplace(c.note);
    Span& span = it->second;
    if (fresh) span.note = c.note, span.first = f;
    span.last = f;
    const bool sounding = c.state == ContactState::kPressed || c.state == ContactState::kOpenString;
    if (sounding && c.string >= 1 && c.string < static_cast<int>(span.string.size())) {
      span.f0_hz.push_back(c.f0_hz);
      ++span.string[static_cast<size_t>(c.string)];
    }
  }
  std::vector<Span> order;
  for (auto& [note, span] : spans) order.push_back(std::move(span));
  std::sort(
      order.begin(), order.end(), [](const Span& a, const Span& b) { return a.first < b.first; });
  const double gap_frames = options.chord_gap_s * input.fps;
  const double lower_frames = options.chord_lower_max_s * input.fps;
  const double tolerance = options.open_tolerance_cents / 100.0;
  int moved = 0;
  for (size_t k = 0; k + 1 < order.size(); ++k) {
    const Span& lower = order[k];
    const size_t length = lower.last - lower.first + 1;
    if (static_cast<double>(length) > lower_frames || lower.f0_hz.empty()) continue;
    // The held pair: the next double-stop note longer than this one (a short note between
    // is the held pair's onset, heard while the window still holds the lower pair).
    size_t u = k + 1;
    while (u < order.size() && order[u].last - order[u].first + 1 <= length &&
           static_cast<double>(order[u].first - lower.last - 1) <= gap_frames) {
      ++u;
    }
    if (u == order.size() || static_cast<double>(order[u].first - lower.last - 1) > gap_frames ||
        order[u].f0_hz.empty()) {
      continue;
    }
    const Span& upper = order[u];
    const int upper_string = static_cast<int>(
        std::max_element(upper.string.begin(), upper.string.end()) - upper.string.begin());
    std::vector<double> f0 = lower.f0_hz;
    const double low1 = UpperMedian(f0);
    f0 = upper.f0_hz;
    const double low2 = UpperMedian(f0);
    const double high1 = note_upper_hz.at(lower.note);
    const double cents = 1200.0 * std::log2(low2 / high1);
    const int string = std::abs(cents) <= 50.0 ? upper_string + 1
                       : cents > 50.0          ? upper_string + 2
                                               : 0;
    if (string < 2 || string > model.num_strings()) continue;
    // Both notes of the lower pair playable there, within a hand's span.
    const double stop1 = SemitonesAboveOpen(model, string, low1);
    const double stop2 = SemitonesAboveOpen(model, string - 1, high1);
    if (stop1 < -tolerance || stop2 < -tolerance ||
        (stop1 > tolerance && stop2 > tolerance &&
         std::abs(stop1 - stop2) > options.max_span_semitones)) {
      continue;
    }
    for (size_t f = lower.first; f <= lower.last; ++f) {
      FrameContact& c1 = out->first[f];
      const bool sounding =
          c1.state == ContactState::kPressed || c1.state == ContactState::kOpenString;
      if (c1.note != lower.note || !sounding || c1.string == string) continue;
      moved += MoveFirstVoice(input, f, string, ik, options, &c1, &out->hand[f]);
    }
  }
  return moved;
}

}  // namespace

Status DoubleStopRefineOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(
      CheckInRange("open_tolerance_cents", open_tolerance_cents, kOpenToleranceRangeCents));
  ARCO_RETURN_IF_ERROR(CheckInRange("max_span_semitones", max_span_semitones, kSpanRangeSemitones));
  ARCO_RETURN_IF_ERROR(CheckInRange("fifth_semitones", fifth_semitones, kSpanRangeSemitones));
  ARCO_RETURN_IF_ERROR(
      CheckInRange("max_tip_distance_mm", max_tip_distance_mm, kTipDistanceRangeMm));
  ARCO_RETURN_IF_ERROR(CheckInRange("chord_gap_s", chord_gap_s, kChordWindowRangeS));
  ARCO_RETURN_IF_ERROR(CheckInRange("chord_lower_max_s", chord_lower_max_s, kChordWindowRangeS));
  ARCO_RETURN_IF_ERROR(CheckInRange("attack_s", attack_s, kAttackRangeS));
  if (max_iterations < 1 || max_iterations > 1000)
    return Status::Error("max_iterations must be in [1, 1000]");
  return Status::Ok();
}

BowRest BowRestOf(const InstrumentModel& model, double inclination_deg) {
  BowRest rest;
  const int n = model.num_strings();
  if (!std::isfinite(inclination_deg) || n < 1) return rest;
  const double incl = inclination_deg * kRadPerDeg;
  double best = std::numeric_limits<double>::infinity();
  for (int s = 1; s <= n; ++s) {  // one string: its own inclination
    const double d = std::abs(incl - model.BowInclinationRad(s));
    if (d < best) {
      best = d;
      rest = {s, 0};
    }
  }
  for (int s = 2; s <= n; ++s) {  // two: the chord of the arch through both, the mean
    const double d =
        std::abs(incl - 0.5 * (model.BowInclinationRad(s) + model.BowInclinationRad(s - 1)));
    if (d < best) {
      best = d;
      rest = {s, s - 1};
    }
  }
  rest.off_deg = best / kRadPerDeg;
  return rest;
}

DoubleStopRefineResult RefineSecondVoice(const RefineInput& input,
                                         const RefineResult& first,
                                         const std::vector<double>& upper_f0_hz,
                                         const DoubleStopRefineOptions& options,
                                         const std::vector<double>& bow_inclination_deg) {
  const Status status = options.Validate();
  if (!status.ok()) throw std::invalid_argument("RefineSecondVoice: " + status.message());
  const size_t frames = input.pitch.size();
  if (first.contacts.size() != frames || first.hand.size() != frames ||
      upper_f0_hz.size() != frames || input.strings_in_world_mm.size() != frames ||
      (!bow_inclination_deg.empty() && bow_inclination_deg.size() != frames)) {
    throw std::invalid_argument("RefineSecondVoice: per-frame inputs differ in length");
  }
  const InstrumentModel& model = *input.instrument;
  const hand::HandModel& hand_model = input.hand_model;
  DoubleStopRefineResult out;
  out.first = first.contacts;
  out.second.assign(frames, FrameContact{});
  out.hand = first.hand;
  hand::FingerIkOptions ik;
  ik.joints = hand::FingerIkJoints::kAll;
  ik.exact_reach = false;
  ik.seed_levels = 0;
  ik.restarts = 0;
  ik.max_iterations = options.max_iterations;
  // Step 00: frames whose bow is on one string have no second voice (and give none to
  // their note's other frames); frames whose bow is on the first voice's string and the
  // next higher one together (on_pair) may get an octave (step 0c).
  std::vector<bool> one_string(frames, false), on_pair(frames, false);
  if (!bow_inclination_deg.empty()) {
    // A note bowed on two strings on most of its frames is a double stop on all of them: a
    // noisy inclination at its start (the violin's fifth G3 + D4 read on the D string
    // alone for its first 6 of 23 frames) does not take its second voice away.
    // Not after the note's last frame on two strings: a double stop's release rings on
    // while the bow leaves the strings or moves to one.
    std::map<int, int> frames_of_note, pair_frames_of_note;
    std::map<int, size_t> last_pair_frame;
    std::vector<BowRest> rests(frames);
    for (size_t f = 0; f < frames; ++f) {
      rests[f] = BowRestOf(model, bow_inclination_deg[f]);
      const int note = first.contacts[f].note;
      if (note < 0) continue;
      ++frames_of_note[note];
      if (rests[f].second_string > 0) {
        ++pair_frames_of_note[note];
        last_pair_frame[note] = f;
      }
    }
    for (size_t f = 0; f < frames; ++f) {
      const BowRest& rest = rests[f];
      const int string = first.contacts[f].string;
      const int note = first.contacts[f].note;
      const bool paired_note = note >= 0 && 2 * pair_frames_of_note[note] > frames_of_note[note] &&
                               f < last_pair_frame[note];
      one_string[f] =
          options.bow_gate && rest.string > 0 && rest.second_string == 0 && !paired_note;
      on_pair[f] = string >= 2 && rest.string == string && rest.second_string == string - 1;
    }
  }
  // A note of the first voice whose frames mostly have an upper note keeps it on the rest
  // of its frames (the polyphonic tracker's window holds two notes only well inside a
  // double stop): its median upper f0, where that lies above the frame's own pitch.
  std::map<int, std::vector<double>> note_upper, note_unheard_octave;
  std::map<int, int> note_frames, note_on_pair;
  std::map<int, size_t> note_first_frame;
  for (size_t f = 0; f < frames; ++f) {
    const int note = first.contacts[f].note;
    if (note < 0) continue;
    note_first_frame.emplace(note, f);
    ++note_frames[note];
    note_on_pair[note] += on_pair[f];
    if (upper_f0_hz[f] > 0 && !one_string[f]) note_upper[note].push_back(upper_f0_hz[f]);
    // Bowed on two strings with one note heard: an octave the spectrum cannot show (0c).
    if (!(upper_f0_hz[f] > 0) && on_pair[f] && first.contacts[f].f0_hz > 0) {
      note_unheard_octave[note].push_back(2.0 * first.contacts[f].f0_hz);
    }
  }
  std::map<int, double> note_median;
  std::map<int, bool> note_agrees;  // two thirds of its upper notes at the median (step 0a)
  for (auto& [note, values] : note_upper) {
    if (2 * static_cast<int>(values.size()) < note_frames[note]) continue;
    // Step 0c in a note heard as two notes: where the frames heard at the octave and the
    // bowed frames heard as one note together put the median at the octave, the octave is
    // the note's upper note (the double bass's A1 + A2, whose A2 the spectrum shows on a
    // third of the frames and a ghost G2 on another third, seed 4).
    const auto unheard = note_unheard_octave.find(note);
    if (options.bow_octaves && unheard != note_unheard_octave.end() &&
        2 * note_on_pair[note] >= note_frames[note]) {
      std::vector<double> with_octaves = values;
      with_octaves.insert(with_octaves.end(), unheard->second.begin(), unheard->second.end());
      const double octave = UpperMedian(unheard->second);
      if (SameUpper(UpperMedian(with_octaves), octave)) {
        values = std::move(with_octaves);
        out.summary.bow_octaves += static_cast<int>(unheard->second.size());
      }
    }
    const double median = UpperMedian(values);
    note_median[note] = median;
    const auto near = std::count_if(values.begin(), values.end(),
                                    [median](double hz) { return SameUpper(hz, median); });
    note_agrees[note] = 3 * near >= 2 * static_cast<int64_t>(values.size());
  }
  const double attack_frames = options.attack_s * input.fps;
  // Step 0c: a note bowed on two strings on most of its frames that the tracker heard as
  // one note is an octave: the upper note's partials are all the lower's even ones, so
  // the spectrum cannot show it (docs/accuracy.md, "Double stops"), but the bow does.
  std::map<int, bool> bow_octave_note;
  if (options.bow_octaves) {
    for (const auto& [note, count] : note_on_pair) {
      if (2 * count >= note_frames[note] && count > 0 && note_median.count(note) == 0) {
        bow_octave_note[note] = true;
      }
    }
  }
  // Chords: the lower pair on the strings its upper pair leaves it.
  if (options.tie_chords) {
    out.summary.chord_frames_moved = TieChords(input, note_median, ik, options, &out);
  }
  // Pass 1: each frame's second voice up to its finger; `stopped` frames need one.
  std::vector<Stop> stops(frames);
  for (size_t f = 0; f < frames; ++f) {
    const FrameContact& c1 = out.first[f];
    double upper = upper_f0_hz[f];
    if (!(upper > 0) && options.fill_notes) {
      const auto it = note_median.find(c1.note);
      if (it != note_median.end() && it->second > 1.03 * c1.f0_hz) upper = it->second;
    }
    if (upper > 0 && c1.note >= 0 && note_agrees[c1.note] && !one_string[f] &&
        static_cast<double>(f - note_first_frame[c1.note]) < attack_frames) {
      const double median = note_median[c1.note];
      if (!SameUpper(upper, median) && median > 1.03 * c1.f0_hz) {
        upper = median;
        ++out.summary.attack_frames;
      }
    }
    const bool octave =
        !(upper > 0) && on_pair[f] && bow_octave_note.count(c1.note) > 0 && c1.f0_hz > 0;
    if (octave) upper = 2.0 * c1.f0_hz;
    const bool sounding =
        c1.state == ContactState::kPressed || c1.state == ContactState::kOpenString;
    if (!(upper > 0) || !sounding || c1.string < 1) continue;
    if (one_string[f]) {
      ++out.summary.bow_one_string;
      continue;
    }
    ++out.summary.frames;
    out.summary.bow_octaves += octave;
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
    c2.point_in_world_mm =
        strings[static_cast<size_t>(string - 1)].PointAtFraction(contact.fraction_from_bridge);
    c2.from_nut_mm = model.string_length_mm() - contact.contact_from_bridge_mm;
    if (!out.hand[f]) {
      c2.reason = ContactReason::kNoHand;
      ++out.summary.uncertain;
      continue;
    }
    stops[f] = {true, first_stop, above_open, 12.0 * std::log2(upper / c1.f0_hz)};
  }

  // Pass 2: the two fingers of each first-voice note and upper semitone (a frame of its
  // own without a note). The first voice's finger may change only in a note whose frames
  // mostly have a second voice: a few frames of an "octave" at a note's edge are more often
  // the note's own 2nd partial than a double stop.
  std::vector<FingerPair> fingers(frames);
  std::map<std::pair<int, long>, std::vector<size_t>> groups;
  std::map<int, int> note_double_frames;
  for (size_t f = 0; f < frames; ++f) {
    if (!stops[f].stopped) continue;
    const int note = first.contacts[f].note;
    groups[{note >= 0 ? note : -1 - static_cast<int>(f), std::lround(stops[f].second)}].push_back(
        f);
    if (note >= 0) ++note_double_frames[note];
  }
  for (const auto& [key, members] : groups) {
    const int note = key.first;
    const bool may_change = note >= 0 && 2 * note_double_frames[note] >= note_frames[note];
    const FingerPair pair =
        ChooseFingers(input, out.first, out.second, out.hand, stops, members, may_change, options);
    for (size_t f : members) fingers[f] = pair;
  }

  // Pass 3: the first voice's finger where the pair changed it, then the second finger.
  for (size_t f = 0; f < frames; ++f) {
    if (!stops[f].stopped) continue;
    FrameContact& c1 = out.first[f];
    FrameContact& c2 = out.second[f];
    const Eigen::Vector3d& point = c2.point_in_world_mm;
    const FingerPair& pair = fingers[f];
    const bool fifth = pair.fifth && c1.pressed();
    const int g1 = pair.first == kOwn ? c1.finger : pair.first;
    int g2 = fifth ? c1.finger : pair.second;
    if (!fifth && (g2 == kNearest || (c1.pressed() && g2 == g1))) {
      g2 = kNearest;  // the nearest fingertip but the first voice's
      double best_mm = 0;
      for (int finger = 1; finger <= 4; ++finger) {
        if (c1.pressed() && finger == g1) continue;
        const double d = TipDistance(hand_model, *out.hand[f], finger, point);
        if (g2 == 0 || d < best_mm) g2 = finger, best_mm = d;
      }
    }
    if (c1.state == ContactState::kPressed && g1 != c1.finger) {
      // The first finger's stop goes to another finger: the old one back where the
      // cameras saw it, the new one to the first voice's contact.
      hand::HandPose pose = *out.hand[f];
      const auto& vision = input.vision_hand[f];
      if (vision) {
        for (int d = 0; d < 4; ++d) {
          const int i =
              hand::DofIndex(static_cast<hand::Finger>(c1.finger), static_cast<hand::FingerDof>(d));
          pose.angles_rad[static_cast<size_t>(i)] = vision->angles_rad[static_cast<size_t>(i)];
        }
      }
      const hand::FingerIkResult r = hand::SolveFingertipIk(
          hand_model, pose, static_cast<hand::Finger>(g1), c1.point_in_world_mm, ik);
      out.hand[f] = r.status.ok() ? r.pose : pose;
      c1.finger = g1;
      if (vision)
        c1.tip_distance_vision_mm = TipDistance(hand_model, *vision, g1, c1.point_in_world_mm);
      c1.tip_distance_refined_mm = TipDistance(hand_model, *out.hand[f], g1, c1.point_in_world_mm);
      ++out.summary.first_fingers_changed;
    }
    const double tip_mm =
        fifth ? c1.tip_distance_refined_mm : TipDistance(hand_model, *out.hand[f], g2, point);
    // A pair of one hand frame was checked for reach over its note (ChooseFingers).
    const bool paired = !fifth && pair.second != kNearest && g2 == pair.second;
    if (!(tip_mm <= options.max_tip_distance_mm || fifth || paired)) {
      c2.reason = ContactReason::kOutOfReach;
      ++out.summary.uncertain;
      continue;
    }
    c2.state = ContactState::kPressed;
    c2.reason = ContactReason::kNone;
    c2.finger = g2;
    c2.tip_distance_vision_mm = tip_mm;
    ++out.summary.pressed;
    if (fifth) {
      ++out.summary.one_finger_fifths;
      c2.tip_distance_refined_mm = c1.tip_distance_refined_mm;
      continue;
    }
    // The second finger to its contact, the first voice's finger untouched.
    const hand::FingerIkResult r =
        hand::SolveFingertipIk(hand_model, *out.hand[f], static_cast<hand::Finger>(g2), point, ik);
    if (r.status.ok()) out.hand[f] = r.pose;
    c2.tip_distance_refined_mm = TipDistance(hand_model, *out.hand[f], g2, point);
    out.summary.joint_limit_violations += hand::CountLimitViolations(hand_model, *out.hand[f]) > 0;
  }
  return out;
}

}  // namespace arco::refine
