// A pitch reference that follows what the soundfont actually plays, for scoring
// trackers on fluidsynth renderings (test_music.h, bench/pitch_peers.sh).
//
// The MIDI score is not exactly what FluidR3 sounds: some samples (notably the
// high violin and viola keys) sit 50-70 cents off their key and carry their own
// slow pitch movement. The "sound" truth corrects the score by each key's own
// contour c_k(tau) in cents, measured on a rendering of that key alone (same
// program and velocity, no bend) with a method that none of the compared
// trackers uses (arco and aubio: YIN difference functions; Praat: windowed
// autocorrelation): a harmonic-peak fit on a long zero-padded FFT.
#pragma once

#include <vector>

#include "arco/audio/harmonic_fit.h"

namespace arco::audio::testing {

// Pitch contour of one key's sample: cents against the key's equal-tempered
// pitch (A4 = 440 Hz) at time tau since the note started sounding.
struct KeyContour {
  double step_s = 0.01;
  std::vector<double> cents;  // cents[i] at tau = i * step_s; NaN: not measured
  // Linear interpolation; NaN outside the contour or next to a NaN sample.
  double At(double tau_s) const;
};

}  // namespace arco::audio::testing
