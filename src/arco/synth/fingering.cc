#include "arco/synth/fingering.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "arco/util/viterbi.h"

namespace arco::synth {
namespace {

struct State {
  NoteFingering f;
  double note_cost = 0;
};

double NoteCost(const NoteFingering& f, const ScoreNote& note, const FingeringOptions& o) {
  if (f.finger == 0) {
    const bool long_note = note.offset_s - note.onset_s >= o.long_note_s;
    return long_note ? o.open_long_note_cost : o.open_string_cost;
  }
  double c = o.position_cost * f.position_semitones;
  if (f.extended) c += o.extension_cost;
  if (f.finger == 4) c += o.fourth_finger_cost;
  return c;
}

double TransitionCost(const State& a,
                      const ScoreNote& na,
                      const State& b,
                      const ScoreNote& nb,
                      const FingeringOptions& o) {
  double c = o.string_crossing_cost * std::abs(a.f.string_index - b.f.string_index);
  const int shift = std::abs(a.f.position_semitones - b.f.position_semitones);
  if (shift > 0) {
    double s = o.shift_cost + o.shift_distance_cost * shift;
    const double gap_s = nb.onset_s - na.offset_s;
    const double ioi_s = nb.onset_s - na.onset_s;
    if (a.f.finger == 0 || b.f.finger == 0 || gap_s >= o.rest_s) {
      s *= o.free_shift_factor;
    } else if (ioi_s < o.fast_note_s) {
      s *= o.fast_shift_factor;
    }
    c += s;
  }
  return c;
}

// True when two spans of one hand frame can stop the two notes of a double stop together:
// one finger stops one place (the same finger on both strings only at the same offset, a
// fifth), and an extended frame does not also hold a finger of the closed frame that the
// extension moves (cello: the extended 2nd finger with the closed 2nd finger).
bool SpansTogether(const FingerSpan& a, const FingerSpan& b, const std::vector<FingerSpan>& frame) {
  if (a.finger == b.finger) return a.offset_semitones == b.offset_semitones;
  if (a.offset_semitones == b.offset_semitones) return false;
  if (a.extended == b.extended) return true;
  const FingerSpan& closed = a.extended ? b : a;
  for (const FingerSpan& s : frame) {
    if (s.extended && s.finger == closed.finger) return false;
  }
  return true;
}

// Candidate states of a double stop: lower note on string s, upper on s + 1, one hand
// position; an open string goes with any position.
void DoubleStopStates(const ScoreNote& note,
                      const ScoreInstrument& instrument,
                      const std::vector<FingerSpan>& frame,
                      const FingeringOptions& options,
                      std::vector<State>* states) {
  const int num_strings = static_cast<int>(instrument.open_string_midi.size());
  auto add = [&](int s, int p, int finger, int a, bool ext, int finger2, int b, bool ext2) {
    NoteFingering f{s, finger, p, a, ext || ext2};
    f.second_string_index = s + 1;
    f.second_finger = finger2;
    f.second_semitone_on_string = b;
    NoteFingering g{s + 1, finger2, p, b, ext2};
    double cost = NoteCost(f, note, options);
    if (finger2 > 0 && finger2 != finger) cost += NoteCost(g, note, options);
    states->push_back({f, cost});
  };
  for (int s = 0; s + 1 < num_strings; ++s) {
    const int a = note.midi_note - instrument.open_string_midi[static_cast<size_t>(s)];
    const int b = note.second_midi_note - instrument.open_string_midi[static_cast<size_t>(s + 1)];
    if (a < 0 || b < 0 || a > instrument.max_semitones_above_open ||
        b > instrument.max_semitones_above_open) {
      continue;
    }
    if (a == 0 && b == 0) {
      for (int p = 1; p <= options.max_position_semitones; ++p) add(s, p, 0, 0, false, 0, 0, false);
      continue;
    }
    for (const FingerSpan& sa : frame) {
      if (a == 0 || b == 0) {
        // One open string: the stopped note sets the position.
        const int p = (a == 0 ? b : a) - sa.offset_semitones;
        if (p < 1 || p > options.max_position_semitones) continue;
        if (a == 0) add(s, p, 0, 0, false, sa.finger, b, sa.extended);
        if (b == 0) add(s, p, sa.finger, a, sa.extended, 0, 0, false);
        continue;
      }
      const int p = a - sa.offset_semitones;
      if (p < 1 || p > options.max_position_semitones) continue;
      for (const FingerSpan& sb : frame) {
        if (b - sb.offset_semitones != p || !SpansTogether(sa, sb, frame)) continue;
        add(s, p, sa.finger, a, sa.extended, sb.finger, b, sb.extended);
      }
    }
  }
}

// The span of `frame` that stops `semitone_on_string` with `finger` in `position` (the
// extended flag of one finger of a double stop, which NoteFingering keeps for the pair).
FingerSpan SpanOf(int finger,
                  int semitone_on_string,
                  int position,
                  const std::vector<FingerSpan>& frame) {
  FingerSpan span{finger, semitone_on_string - position, false};
  for (const FingerSpan& s : frame) {
    if (s.finger == finger && s.offset_semitones == span.offset_semitones)
      span.extended = s.extended;
  }
  return span;
}

// True when one hand can hold a rolled chord's two pairs (ScoreNote::chord_upper_pair) down
// together from the chord's start: the same position, the upper pair on the lower pair's
// upper string (sharing that note, a 3-note chord) or on the next strings (a 4-note chord),
// and every two stopped places of different strings playable together (SpansTogether; one
// finger stops two strings only side by side, a fifth).
bool ChordHoldable(const NoteFingering& lower,
                   const NoteFingering& upper,
                   const std::vector<FingerSpan>& frame) {
  if (upper.position_semitones != lower.position_semitones) return false;
  const bool shared = upper.string_index == lower.second_string_index;
  if (!shared && upper.string_index != lower.second_string_index + 1) return false;
  if (shared && upper.finger != lower.second_finger) return false;
  struct Place {
    int string, finger, semitone;
  };
  std::vector<Place> places = {
      {lower.string_index, lower.finger, lower.semitone_on_string},
      {lower.second_string_index, lower.second_finger, lower.second_semitone_on_string}};
  if (!shared) places.push_back({upper.string_index, upper.finger, upper.semitone_on_string});
  places.push_back(
      {upper.second_string_index, upper.second_finger, upper.second_semitone_on_string});
  const int p = lower.position_semitones;
  for (size_t i = 0; i < places.size(); ++i) {
    for (size_t j = i + 1; j < places.size(); ++j) {
      const Place& a = places[i];
      const Place& b = places[j];
      if (a.finger == 0 || b.finger == 0) continue;
      if (a.finger == b.finger && std::abs(a.string - b.string) != 1) return false;
      if (!SpansTogether(SpanOf(a.finger, a.semitone, p, frame),
                         SpanOf(b.finger, b.semitone, p, frame),
                         frame)) {
        return false;
      }
    }
  }
  return true;
}

}  // namespace

Status FingeringOptions::Validate() const {
  if (max_position_semitones < 1 || max_position_semitones > 36) {
    return Status::Error("fingering: max_position_semitones must be in 1..36");
  }
  for (double v : {position_cost,
                   shift_cost,
                   shift_distance_cost,
                   free_shift_factor,
                   rest_s,
                   fast_note_s,
                   fast_shift_factor,
                   string_crossing_cost,
                   extension_cost,
                   open_string_cost,
                   open_long_note_cost,
                   long_note_s,
                   fourth_finger_cost}) {
    if (!(v >= 0) || !std::isfinite(v)) {
      return Status::Error("fingering: every cost and duration must be finite and >= 0");
    }
  }
  return Status::Ok();
}

const std::vector<FingerSpan>& HandFrameFor(const std::string& name) {
  const StatusOr<InstrumentKind> kind = ParseInstrumentKind(name);
  if (!kind.ok()) throw std::invalid_argument("HandFrameFor: " + kind.status().message());
  return GetInstrumentInfo(*kind).hand_frame;
}

StatusOr<FingeringPlan> PlanFingering(const Score& score,
                                      const ScoreInstrument& instrument,
                                      const FingeringOptions& options) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  const std::vector<FingerSpan>& frame = HandFrameFor(instrument.name);
  const size_t n = score.notes.size();
  const int num_strings = static_cast<int>(instrument.open_string_midi.size());
  // Candidate states per note.
  std::vector<std::vector<State>> states(n);
  for (size_t i = 0; i < n; ++i) {
    const ScoreNote& note = score.notes[i];
    if (note.IsDoubleStop()) DoubleStopStates(note, instrument, frame, options, &states[i]);
    for (int s = 0; s < num_strings && !note.IsDoubleStop(); ++s) {
      const int semis = note.midi_note - instrument.open_string_midi[static_cast<size_t>(s)];
      if (semis < 0 || semis > instrument.max_semitones_above_open) continue;
      if (semis == 0) {
        // Open string: the hand stays in any position (chosen by the transitions).
        for (int p = 1; p <= options.max_position_semitones; ++p) {
          NoteFingering f{s, 0, p, 0, false};
          states[i].push_back({f, NoteCost(f, note, options)});
        }
        continue;
      }
      for (const FingerSpan& span : frame) {
        const int p = semis - span.offset_semitones;
        if (p < 1 || p > options.max_position_semitones) continue;
        NoteFingering f{s, span.finger, p, semis, span.extended};
        states[i].push_back({f, NoteCost(f, note, options)});
      }
    }
    if (states[i].empty()) {
      char buf[200];
      const std::string name =
          MidiNoteName(note.midi_note) +
          (note.IsDoubleStop() ? "+" + MidiNoteName(note.second_midi_note) : std::string());
      std::snprintf(buf,
                    sizeof(buf),
                    "note %d (%s) at %.3f s cannot be fingered on the %s within position %d",
                    note.midi_note,
                    name.c_str(),
                    note.onset_s,
                    instrument.name.c_str(),
                    options.max_position_semitones);
      return Status::Error(buf);
    }
  }
  FingeringPlan plan;
  if (n == 0) return plan;
  // Viterbi over the notes (util/viterbi.h: ties to the lower state index).
  std::vector<int> num_states(n);
  for (size_t i = 0; i < n; ++i) num_states[i] = static_cast<int>(states[i].size());
  const ViterbiPath path = DecodeViterbi(
      num_states,
      [&](size_t i, int k) { return states[i][static_cast<size_t>(k)].note_cost; },
      [&](size_t i, int j, int k) {
        if (score.notes[i].chord_upper_pair &&
            !ChordHoldable(states[i - 1][static_cast<size_t>(j)].f,
                           states[i][static_cast<size_t>(k)].f,
                           frame)) {
          return std::numeric_limits<double>::infinity();
        }
        return TransitionCost(states[i - 1][static_cast<size_t>(j)],
                              score.notes[i - 1],
                              states[i][static_cast<size_t>(k)],
                              score.notes[i],
                              options);
      });
  if (!std::isfinite(path.total_cost)) {
    return Status::Error("a chord's two pairs cannot be held in one hand position on the " +
                         instrument.name);
  }
  plan.total_cost = path.total_cost;
  plan.notes.resize(n);
  for (size_t i = 0; i < n; ++i) {
    plan.notes[i] = states[i][static_cast<size_t>(path.states[i])].f;
  }
  for (size_t i = 0; i < n; ++i) {
    if (plan.notes[i].finger == 0) ++plan.num_open_strings;
    if (i == 0) continue;
    if (plan.notes[i].position_semitones != plan.notes[i - 1].position_semitones) ++plan.num_shifts;
    if (plan.notes[i].string_index != plan.notes[i - 1].string_index) ++plan.num_string_crossings;
  }
  return plan;
}

}  // namespace arco::synth
