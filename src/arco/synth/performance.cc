#include "arco/synth/performance.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "arco/registry/instruments.h"
#include "arco/synth/random.h"

namespace arco::synth {
namespace {

constexpr double kTwoPi = 6.283185307179586;

// Smooth 0 -> 1 ramp (cubic smoothstep) so the pitch has no kink at the start.
double SmoothRamp(double x) {
  if (x <= 0) return 0;
  if (x >= 1) return 1;
  return x * x * (3 - 2 * x);
}

}  // namespace

Status ExpressionOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(CheckInRange("a4_hz", a4_hz, kA4RangeHz));
  if (!(intonation_sigma_cents >= 0) || !(max_intonation_cents >= 0) || max_intonation_cents > 50) {
    return Status::Error("intonation: sigma >= 0 and max in [0, 50] cents");
  }
  if (!(vibrato_rate_min_hz > 0) || !(vibrato_rate_max_hz >= vibrato_rate_min_hz) ||
      vibrato_rate_max_hz > 15) {
    return Status::Error("vibrato rate: 0 < min <= max <= 15 Hz");
  }
  if (!(vibrato_extent_min_cents >= 0) || !(vibrato_extent_max_cents >= vibrato_extent_min_cents) ||
      vibrato_extent_max_cents > 100) {
    return Status::Error("vibrato extent: 0 <= min <= max <= 100 cents");
  }
  if (!(vibrato_min_note_s >= 0) || !(vibrato_delay_s >= 0) || !(vibrato_ramp_s > 0)) {
    return Status::Error("vibrato timing: durations must be >= 0 (ramp > 0)");
  }
  return Status::Ok();
}

double PerformedNote::VibratoCentsOnlyAt(double time_s) const {
  if (vibrato_rate_hz <= 0) return 0;
  const double tv = note.onset_s + vibrato_delay_s;
  const double ramp = SmoothRamp((time_s - tv) / vibrato_ramp_s);
  if (ramp <= 0) return 0;
  return vibrato_extent_cents * ramp * std::sin(kTwoPi * vibrato_rate_hz * (time_s - tv));
}

double PerformedNote::CentsAt(double time_s) const {
  return intonation_cents + VibratoCentsOnlyAt(time_s);
}

double PerformedNote::SecondCentsAt(double time_s) const {
  if (fingering.second_finger == 0) return 0;
  return second_intonation_cents + VibratoCentsOnlyAt(time_s);
}

int Performance::NoteIndexAt(double time_s) const {
  // Notes are sorted and disjoint: binary search on onsets.
  auto it =
      std::upper_bound(notes.begin(), notes.end(), time_s, [](double t, const PerformedNote& n) {
        return t < n.note.onset_s;
      });
  if (it == notes.begin()) return -1;
  const auto i = static_cast<int>(std::distance(notes.begin(), it)) - 1;
  return time_s < notes[static_cast<size_t>(i)].note.offset_s ? i : -1;
}

double Performance::MidiPitchAt(double time_s) const {
  const int i = NoteIndexAt(time_s);
  if (i < 0) return std::numeric_limits<double>::quiet_NaN();
  const PerformedNote& n = notes[static_cast<size_t>(i)];
  return n.note.midi_note + n.CentsAt(time_s) / 100.0;
}

double Performance::F0HzAt(double time_s) const {
  const double m = MidiPitchAt(time_s);
  return std::isnan(m) ? 0.0 : MidiToHz(m, a4_hz);
}

double Performance::SecondF0HzAt(double time_s) const {
  const int i = NoteIndexAt(time_s);
  if (i < 0) return 0;
  const PerformedNote& n = notes[static_cast<size_t>(i)];
  if (!n.note.IsDoubleStop()) return 0;
  return MidiToHz(n.note.second_midi_note + n.SecondCentsAt(time_s) / 100.0, a4_hz);
}

StatusOr<Performance> MakePerformance(const Score& score,
                                      const FingeringPlan& plan,
                                      const ExpressionOptions& options,
                                      uint64_t seed) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  if (plan.notes.size() != score.notes.size()) {
    throw std::invalid_argument("MakePerformance: fingering plan and score differ in length");
  }
  Rng rng = Rng::Stream(seed, 101);
  Performance perf;
  perf.a4_hz = options.a4_hz;
  perf.duration_s = score.duration_s;
  for (size_t i = 0; i < score.notes.size(); ++i) {
    PerformedNote p;
    p.note = score.notes[i];
    p.fingering = plan.notes[i];
    // Draw every value for every note, used or not, so one option does not
    // shift the random stream of the others.
    const double into = rng.Normal(0, options.intonation_sigma_cents);
    const double rate = rng.Uniform(options.vibrato_rate_min_hz, options.vibrato_rate_max_hz);
    const double extent =
        rng.Uniform(options.vibrato_extent_min_cents, options.vibrato_extent_max_cents);
    if (p.note.IsDoubleStop() != p.fingering.IsDoubleStop()) {
      throw std::invalid_argument("MakePerformance: a double stop fingered as a single note");
    }
    // A double stop draws one more value (single-note scores keep their stream).
    if (p.note.IsDoubleStop()) {
      const double into2 = rng.Normal(0, options.intonation_sigma_cents);
      if (p.fingering.second_finger > 0) {
        p.second_intonation_cents =
            std::clamp(into2, -options.max_intonation_cents, options.max_intonation_cents);
      }
    }
    const bool open = p.fingering.finger == 0;
    if (!open) {
      p.intonation_cents =
          std::clamp(into, -options.max_intonation_cents, options.max_intonation_cents);
      const double dur = p.note.offset_s - p.note.onset_s;
      if (options.vibrato && dur >= options.vibrato_min_note_s && extent > 0) {
        p.vibrato_rate_hz = rate;
        p.vibrato_extent_cents = extent;
        p.vibrato_delay_s = options.vibrato_delay_s;
        p.vibrato_ramp_s = options.vibrato_ramp_s;
      }
    }
    perf.notes.push_back(p);
  }
  return perf;
}

}  // namespace arco::synth
