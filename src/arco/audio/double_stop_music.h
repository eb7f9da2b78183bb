// Double-stop test music with known truth: sixths, thirds, fifths and octaves on adjacent
// strings of an instrument, with a single note after each, rendered by additive synthesis
// (a stand-in for `arco synth --piece double-stops`, whose score holds one note at a time).
//
// Each voice: partials k = 1..20 below 0.45 fs with amplitude k^-1 times a seeded jitter
// of +-4 dB per note and partial (the uneven spectra of real strings, which the spectral
// smoothness rule must survive), random phases, a 30 ms attack and release, every third
// note with vibrato (5.5 Hz, +-20 cents, both voices alike); the upper voice 0.5 to 1.0
// times the lower's loudness; white noise at -60 dBFS. Notes last 0.6-1.0 s with a 0.2 s
// gap (0.8 s after every fifth note); a note is scored from onset + edge to offset - edge, silence
// from an edge after an offset to an edge before the next onset.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace arco::audio::testing {

struct DoubleStopNote {
  double onset_s = 0, offset_s = 0;
  int low_midi = 0;
  int high_midi = 0;  // 0: a single note
  bool vibrato = false;
};

struct DoubleStopMusic {
  std::string instrument;
  std::vector<DoubleStopNote> notes;
  double duration_s = 0;
  // -1 unscored, 0 silence, 1 single note, 2 double stop; f0s in Hz (high 0 unless 2).
  // Frames within edge_s of an onset or offset are unscored (at least 60 ms; an analysis
  // window of length w needs w / 2).
  int Truth(double time_s, double* low_hz, double* high_hz, double edge_s = 0.06) const;
};

// violin | viola | cello | double_bass: `notes` notes, every other one a double stop
// (cycling sixth, third, fifth, octave) on a random pair of adjacent strings in the
// first positions, the others single notes on a random string.
DoubleStopMusic MakeDoubleStopMusic(const std::string& instrument, int notes, uint32_t seed);

// Mono samples of the music at sample_rate_hz.
std::vector<float> RenderDoubleStopMusic(const DoubleStopMusic& music,
                                         int sample_rate_hz,
                                         uint32_t seed);

}  // namespace arco::audio::testing
