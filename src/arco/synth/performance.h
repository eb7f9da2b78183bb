// A performance: a fingered score plus expression (intonation, vibrato), i.e.
// the exact pitch the synthetic player produces at every instant. The audio is
// rendered from it and the left hand follows it, so both agree by construction.
//
// Pitch of note i at time t, in cents relative to equal temperament at a4_hz:
//   cents(t) = intonation_cents + extent_cents * ramp(t) * sin(2 pi rate_hz (t - t_v))
// with t_v = onset + vibrato_delay_s and ramp rising smoothly from 0 to 1 over
// vibrato_ramp_s after t_v (a player starts a long note straight, then vibrates).
// Open strings have neither intonation error nor vibrato. The upper note of a double stop
// (fingering.second_finger, score second_midi_note) has its own intonation and, when
// stopped, the first note's vibrato (one hand rocks both fingers); a double stop whose
// lower note is open has no vibrato.
#pragma once

#include <cstdint>
#include <vector>

#include "arco/synth/fingering.h"
#include "arco/synth/score.h"
#include "arco/util/status.h"

namespace arco::synth {

struct ExpressionOptions {
  double a4_hz = 440.0;
  double intonation_sigma_cents = 6.0;  // per-note deviation, Gaussian ...
  double max_intonation_cents = 15.0;   // ... clipped to +-this
  double vibrato_min_note_s = 0.45;     // stopped notes at least this long vibrate
  double vibrato_rate_min_hz = 5.0;     // rate drawn per note in [min, max]
  double vibrato_rate_max_hz = 6.5;
  double vibrato_extent_min_cents = 12;  // half peak-to-peak, drawn per note
  double vibrato_extent_max_cents = 30;
  double vibrato_delay_s = 0.12;  // straight tone before the vibrato starts
  double vibrato_ramp_s = 0.25;   // fade-in of the extent
  bool vibrato = true;
  Status Validate() const;
};

struct PerformedNote {
  ScoreNote note;
  NoteFingering fingering;
  double intonation_cents = 0;
  double vibrato_rate_hz = 0;       // 0 = no vibrato
  double vibrato_extent_cents = 0;  // half peak-to-peak
  double vibrato_delay_s = 0;
  double vibrato_ramp_s = 0.25;
  double second_intonation_cents = 0;  // the double stop's upper note

  // Cents from equal temperament at time t (t inside the note).
  double CentsAt(double time_s) const;
  // The same for the double stop's upper note (0 on an open string).
  double SecondCentsAt(double time_s) const;
  // d(cents)/dt, for rocking the hand in phase with the pitch.
  double VibratoCentsOnlyAt(double time_s) const;
};

struct Performance {
  std::vector<PerformedNote> notes;
  double duration_s = 0;
  double a4_hz = 440.0;

  // Index of the note sounding at `time_s` (onset <= t < offset), or -1.
  int NoteIndexAt(double time_s) const;
  // The sounding f0 in Hz at `time_s`, or 0 when silent.
  double F0HzAt(double time_s) const;
  // The f0 of a double stop's upper note at `time_s`, or 0 when none sounds.
  double SecondF0HzAt(double time_s) const;
  // Fractional MIDI pitch (midi_note + cents / 100) at `time_s`, or NaN.
  double MidiPitchAt(double time_s) const;
};

// Draws intonation and vibrato per note from `seed` (deterministic).
StatusOr<Performance> MakePerformance(const Score& score,
                                      const FingeringPlan& plan,
                                      const ExpressionOptions& options,
                                      uint64_t seed);

}  // namespace arco::synth
