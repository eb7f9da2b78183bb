// Audio of a synthetic performance: the performance is written as a Standard
// MIDI File with pitch bends (audio/midi_file.h) and rendered by Debian's
// fluidsynth with real instrument samples:
//   fluidsynth -ni -q -R 0 -C 0 -r RATE -F out.wav SOUNDFONT in.mid
// (reverb and chorus off so the pitch stays clean).
//
// Pitch bends carry the truth pitch every `bend_step_s` (intonation and
// vibrato, in semitones relative to the written note, +-2 semitone range).
// Every note starts with All Sound Off (CC 120) so releases do not overlap.
// Sample pitch: the soundfont's samples are neither exactly in tune (FluidR3 sits
// within about +-15 cents of equal temperament, see audio/test_music.h) nor
// steady: FluidR3's string samples were recorded with the player's own vibrato
// (+-10-15 cents at ~5 Hz; its SF2 zones carry no LFO). With `tune_soundfont`,
// each distinct key is first rendered alone for as long as its longest note and
// measured with the harmonic-peak fit (audio/harmonic_fit.h; deliberately not
// arco's pitch tracker, which is scored against this audio): its pitch contour
// c_k(tau) in cents against
// equal temperament, tau = time into the sample. The bends then subtract
// c_k(tau_s(t)), where tau_s advances at the bent playback rate 2^(bend/12), so
// the rendered audio sounds the truth pitch.
// Events are written `latency_s` early to cancel fluidsynth's output latency
// (about 3 ms, measured in audio/test_music.h).
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "arco/audio/midi_file.h"
#include "arco/synth/performance.h"
#include "arco/util/status.h"

namespace arco::synth {

struct AudioRenderOptions {
  std::string soundfont = "/usr/share/sounds/sf2/FluidR3_GM.sf2";
  int sample_rate_hz = 48000;
  double bend_step_s = 0.005;
  bool tune_soundfont = true;
  double latency_s = 0.003;
  double room_noise_dbfs = 0;  // room noise RMS level; 0 = none (e.g. -50 for a quiet room)
  Status Validate() const;
};

// Measured pitch of one key's sample: cents against ET every step_s of sample time.
struct SampleContour {
  double step_s = 0.005;
  std::vector<double> cents;
  double median_cents = 0;
  double At(double sample_time_s) const;  // clamped to the ends; 0 when empty
};

struct AudioRenderSummary {
  std::map<int, double> key_offset_cents;  // median sample detuning per MIDI key
  double duration_s = 0;
  std::string midi_path;
};

// The MIDI file for a performance; `contours` (may be empty) are compensated
// as described above.
audio::MidiFile PerformanceToMidi(const Performance& performance,
                                  int gm_program,
                                  const std::map<int, SampleContour>& contours,
                                  const AudioRenderOptions& options);

// Renders `performance` to `wav_path` (16-bit PCM, stereo as fluidsynth writes
// it), leaving the MIDI file at `midi_path`. `work_dir` holds temporary files.
Status RenderPerformanceAudio(const Performance& performance,
                              int gm_program,
                              const AudioRenderOptions& options,
                              const std::string& work_dir,
                              const std::string& midi_path,
                              const std::string& wav_path,
                              uint64_t seed,
                              AudioRenderSummary* summary);

}  // namespace arco::synth
