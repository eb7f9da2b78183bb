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
    for (int s = 0; s < num_strings; ++s) {
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
      std::snprintf(buf,
                    sizeof(buf),
                    "note %d (%s) at %.3f s cannot be fingered on the %s within position %d",
                    note.midi_note,
                    MidiNoteName(note.midi_note).c_str(),
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
        return TransitionCost(states[i - 1][static_cast<size_t>(j)],
                              score.notes[i - 1],
                              states[i][static_cast<size_t>(k)],
                              score.notes[i],
                              options);
      });
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
