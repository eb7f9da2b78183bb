#include "arco/synth/fingering.h"

#include <cmath>
#include <limits>
#include <stdexcept>

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

std::vector<FingerSpan> HandFrameFor(const std::string& name) {
  if (name == "cello") {
    return {{1, 0, false},
            {2, 1, false},
            {3, 2, false},
            {4, 3, false},
            {2, 2, true},
            {3, 3, true},
            {4, 4, true}};
  }
  if (name == "violin" || name == "viola") {
    return {{1, 0, false},
            {2, 1, false},
            {2, 2, false},
            {3, 3, false},
            {3, 4, false},
            {4, 5, false},
            {4, 6, true}};
  }
  if (name == "double_bass" || name == "contrabass" || name == "bass") {
    return {{1, 0, false}, {2, 1, false}, {4, 2, false}};
  }
  throw std::invalid_argument("HandFrameFor: unknown instrument '" + name + "'");
}

StatusOr<FingeringPlan> PlanFingering(const Score& score,
                                      const ScoreInstrument& instrument,
                                      const FingeringOptions& options) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  const std::vector<FingerSpan> frame = HandFrameFor(instrument.name);
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
  // Viterbi: best[i][k] = cost of the cheapest plan for notes 0..i ending in state k.
  std::vector<std::vector<double>> best(n);
  std::vector<std::vector<int>> back(n);
  best[0].resize(states[0].size());
  back[0].assign(states[0].size(), -1);
  for (size_t k = 0; k < states[0].size(); ++k) best[0][k] = states[0][k].note_cost;
  for (size_t i = 1; i < n; ++i) {
    best[i].assign(states[i].size(), std::numeric_limits<double>::infinity());
    back[i].assign(states[i].size(), -1);
    for (size_t k = 0; k < states[i].size(); ++k) {
      for (size_t j = 0; j < states[i - 1].size(); ++j) {
        const double c =
            best[i - 1][j] +
            TransitionCost(
                states[i - 1][j], score.notes[i - 1], states[i][k], score.notes[i], options);
        if (c < best[i][k]) {
          best[i][k] = c;
          back[i][k] = static_cast<int>(j);
        }
      }
      best[i][k] += states[i][k].note_cost;
    }
  }
  int k = 0;
  for (size_t j = 1; j < best[n - 1].size(); ++j) {
    if (best[n - 1][j] < best[n - 1][static_cast<size_t>(k)]) k = static_cast<int>(j);
  }
  plan.total_cost = best[n - 1][static_cast<size_t>(k)];
  plan.notes.resize(n);
  for (size_t i = n; i-- > 0;) {
    plan.notes[i] = states[i][static_cast<size_t>(k)].f;
    k = back[i][static_cast<size_t>(k)];
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
