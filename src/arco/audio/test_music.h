// Test music with known pitch truth: a seeded melody per instrument written as
// MIDI (with pitch-bend vibrato and glides), rendered by the fluidsynth CLI with
// the Debian FluidR3_GM soundfont. Used by the render tests and bench/pitch_peers.sh.
//
// Measured on Debian 12 (fluidsynth 2.3, FluidR3_GM): output starts about 3 ms
// after the MIDI event (kFluidsynthLatencyS), the string samples need 20-50 ms
// to speak and release over a few hundred ms, and the sampled notes sit within
// about +-15 cents of equal temperament. Truth therefore counts a note as
// voiced from onset + 60 ms to offset - 30 ms and unvoiced only from offset +
// 0.7 s until the next onset; everything else is not scored. Each note starts
// with All Sound Off (CC 120) so the previous note's release does not overlap.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "arco/audio/midi_file.h"
#include "arco/audio/sound_truth.h"
#include "arco/util/status.h"

namespace arco::audio::testing {

constexpr double kFluidsynthLatencyS = 0.003;
constexpr const char* kSoundfont = "/usr/share/sounds/sf2/FluidR3_GM.sf2";

enum class TruthVoicing { kVoiced, kUnvoiced, kUnscored };

struct TestMusic {
  std::string instrument;
  MidiFile midi;
  double duration_s = 0;
  // Truth at time t (audio clock of the rendering): f0 in Hz when voiced.
  TruthVoicing Voicing(double time_s) const;
  double F0Hz(double time_s) const;  // 0 unless Voicing() == kVoiced
  // Notes the soundfont did not sound (FluidR3's violin has no sample for some
  // high keys, e.g. A#6): not scored. Filled by MarkSilentNotes.
  std::vector<char> silent;
  // Each key's own pitch contour (sound_truth.h), filled by MeasureKeyContours.
  std::map<int, KeyContour> key_contours;
  // "Sound" truth: F0Hz corrected by the key's contour at the sample time tau
  // since the note started (tau runs at 2^(bend/12) per second, as fluidsynth
  // plays a bent sample faster). 0 unless voiced and the contour is measured.
  double SoundF0Hz(double time_s) const;
};

// Marks notes whose rendering stays below -45 dBFS RMS over their scored span.
Status MarkSilentNotes(const std::string& wav_path, TestMusic* music);

// violin | viola | cello | bass. About `notes` notes across the instrument's
// range, every third with vibrato (5-6.5 Hz, 20-40 cents), one glide per ten
// notes, a rest of >= 1 s after every sixth note.
TestMusic MakeTestMusic(const std::string& instrument, int notes, uint32_t seed);

// Renders every key of the music alone (same program and velocity, no bends,
// into WORK_DIR/INSTRUMENT_keys.wav) and measures its contour with
// HarmonicPeakFit every 10 ms over the longest duration the key is played.
Status MeasureKeyContours(const std::string& work_dir, TestMusic* music);

// time_s,f0_hz,voicing (1 voiced, 0 unvoiced, -1 unscored) every 1/rate_hz;
// f0 from SoundF0Hz when `sound` (voiced rows without a measured contour are
// then unscored).
Status WriteTruthCsv(const std::string& path,
                     const TestMusic& music,
                     double rate_hz,
                     bool sound = false);

// fluidsynth -ni -R 0 -C 0 -r RATE -F wav soundfont midi; error if it fails.
Status RenderWithFluidsynth(const std::string& midi_path,
                            const std::string& wav_path,
                            int sample_rate_hz = 44100);

}  // namespace arco::audio::testing
