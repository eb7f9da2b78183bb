// Up to two simultaneous notes per video frame (double stops of a bowed string), beside the
// single-note tracker (pitch_tracker.h), which it does not change.
//
// Method (docs/audio.md, "Double stops"): Hann-windowed magnitude spectrum (FFTW); the
// harmonic-sum salience of every candidate f0 on a grid over the instrument's range,
//   s(f) = sum_{m=1..M} g(f, m) max_{k in band(m f)} |X(k)|,  g(f, m) = (f + a) / (m f + b)
// (Klapuri 2006, "Multiple fundamental frequency estimation by summing harmonic
// amplitudes", eq. 3, a = 52 Hz, b = 320 Hz); the best candidate whose fundamental is
// present is the first note; its partials are cancelled from the spectrum after the
// spectral-smoothness rule (Klapuri 2003, "Multiple fundamental frequency estimation based
// on harmonicity and spectral smoothness": a partial's amplitude is limited to the
// geometric mean of its neighbours', so a partial shared with a second note keeps that
// note's share); the
// best candidate on the residual is the second note when
//   (1) it forms a playable double stop with the first: the two notes lie on adjacent
//       strings, each at or above its open string, and their stops lie within
//       max_span_semitones of each other along the fingerboard (PlayableDoubleStop);
//   (2) its fundamental is present in the residual (kills the sub-octave, sub-fifth and
//       fifth-above ghosts of a single note, whose fundamentals are no partial): a peak
//       (BandPeak), not the slope of a neighbour's;
//   (3) its residual salience is at least second_min_ratio of the first note's;
//   (4) then, for each note of the pair, its octave below replaces it when that forms a
//       playable pair with the partner, its fundamental is present and its odd partials
//       (which the heard note does not have) are strong on the spectrum without the
//       partner: a note with a weak fundamental heard as its own 2nd partial;
//   (5) before (4), a pair a fifth apart whose octave below has a present fundamental and
//       strong partials prime to 6 (neither heard note's) is that one note, heard as its
//       2nd and 3rd partials.
// Besides, per pair of adjacent strings, the pair heard as played on them
// (PolyPitchFrame::on_strings): the free pair where it can be played there, else the pair
// with one note on each string that explains most of the spectrum (PairOnStrings). The
// refinement takes the pair of the strings the bow rests on (docs/audio.md, "The pair on
// the bowed strings").
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "arco/audio/audio_reader.h"
#include "arco/audio/notes.h"
#include "arco/audio/pitch_tracker.h"
#include "arco/util/number_range.h"
#include "arco/util/status.h"

namespace arco::audio {

// Declared ranges of DoubleStopOptions (Validate()).
inline constexpr NumberRange kDoubleStopWindowRangeS = Closed(0, 0.5);
inline constexpr NumberRange kDoubleStopHarmonicsRange = Closed(1, 40);
inline constexpr NumberRange kDoubleStopGridRangeCents = Closed(1, 50);
inline constexpr NumberRange kDoubleStopRatioRange = Closed(0, 1);
inline constexpr NumberRange kDoubleStopSpanRangeSemitones = Closed(0, 24);
inline constexpr NumberRange kDoubleStopSilenceRangeDb = Closed(-120, 0);
inline constexpr NumberRange kDoubleStopConsistencyRangeS = Closed(0, 2);

struct DoubleStopOptions {
  InstrumentRange range;    // f0 limits and analysis rate (InstrumentRangeByName)
  double fps = 30.0;        // frame times as the tracker's: start_s + i / fps
  double start_s = 0.0;     // audio time of frame 0
  int64_t max_frames = -1;  // -1: to the end of the audio
  double a4_hz = 440.0;     // tuning of the open strings (string prior)
  // Hann window (zero-padded to >= 2x for the FFT); 0: DoubleStopWindowS's choice.
  double window_s = 0.0;
  int harmonics = 12;       // M: partials summed per candidate
  double grid_cents = 5.0;  // candidate spacing (f0 then refined from the partials)
  // Second note kept when its residual salience >= this times the salience cancelled as
  // the first note's own (so an octave's shared partials do not count against it).
  double second_min_ratio = 0.3;
  // A candidate's fundamental must reach this fraction of the window's strongest peak.
  double min_fundamental_ratio = 0.05;
  // Largest distance along the fingerboard between the two stops (semitones from the
  // nut): 7 spans unisons (open string + 4th finger) to octaves (1st + 4th finger).
  double max_span_semitones = 7.0;
  double silence_db = -50.0;  // window RMS below this (dBFS): no note
  // ConsistentDoubleStops' window each side, after the frames are analysed (rounded to
  // frames at fps; 0: off). 0.17 s (5 frames at 30 fps): on the synthetic double-stop
  // pieces 3 frames left alternations of the viola's thirds, 8 and 12 took the bass's
  // pairs across note changes (docs/audio.md, "Double stops").
  double consistency_s = 0.17;
  Status Validate() const;
};

struct PolyNote {
  double f0_hz = 0;
  double salience = 0;  // s(f) of eq. 3 (on the residual for the second note)
};

// Pairs of adjacent strings of a four-string instrument (PolyPitchFrame::on_strings).
inline constexpr int kStringPairs = 3;

struct PolyPitchFrame {
  int64_t frame = 0;
  double time_s = 0;
  int count = 0;                  // notes found: 0, 1 or 2
  std::array<PolyNote, 2> notes;  // the first `count`, lower f0 first
  // The pair heard as played on strings s + 1 and s (1 = highest), lower f0 first, at
  // on_strings[s - 1] (DoubleStopAnalyzer::Analyze: `notes` when they can be played there,
  // else the best joint explanation with one note on each string); f0 0 where none is
  // playable or the window is silent. The bow
  // says which strings sound (refine/double_stop_refine.h, bow_pairs).
  std::array<std::array<PolyNote, 2>, kStringPairs> on_strings{};
};

struct DoubleStopSummary {
  int64_t frames = 0;
  int64_t silent_frames = 0, single_frames = 0, double_frames = 0;
  double cpu_seconds = 0;  // informational
};

// The analysis window: window_s, or when 0, 8 periods of the lowest f0 and at least 0.1 s
// (violin 0.1 s, cello 0.127 s, double bass 0.205 s).
double DoubleStopWindowS(const DoubleStopOptions& options);

// True when MIDI pitches low < high (fractional) can be stopped on adjacent strings
// s, s + 1 of `open_midi_low_to_high` with both stops at or above the nut (50 cents of
// tolerance) and |stop(high) - stop(low)| <= max_span_semitones.
bool PlayableDoubleStop(const std::array<double, 4>& open_midi_low_to_high,
                        double low_midi,
                        double high_midi,
                        double max_span_semitones);

// The largest magnitude of spectrum[lo..hi] when it is a local maximum of the spectrum
// (a peak inside the band); 0 when the band only holds the slope of a peak outside it (a
// neighbouring partial's main lobe, or the smear of an onset inside the window); -1 for a
// band outside the spectrum. A candidate's fundamental is present only as such a peak.
double BandPeak(const std::vector<double>& spectrum, int lo, int hi);

// One window at a time; buffers and the FFT plan are made once (options validated by the
// caller: the constructor throws std::invalid_argument on invalid options).
class DoubleStopAnalyzer {
 public:
  explicit DoubleStopAnalyzer(const DoubleStopOptions& options);
  ~DoubleStopAnalyzer();
  DoubleStopAnalyzer(const DoubleStopAnalyzer&) = delete;
  DoubleStopAnalyzer& operator=(const DoubleStopAnalyzer&) = delete;

  int window_length() const { return window_; }
  // True when `pair` (lower f0 first) can be played on strings upper_string + 1 and
  // upper_string (1 = highest): the lower note from the nut to kPairMaxStopSemitones up the
  // lower string, the upper likewise on the upper one, the stops within max_span_semitones.
  // False without the instrument's strings or for a string outside 1..kStringPairs.
  bool FitsStrings(const std::array<PolyNote, 2>& pair, int upper_string) const;
  // Notes of x[0..window_length()), lower f0 first; returns their count. With on_strings,
  // also the pair on each pair of adjacent strings (PairOnStrings; zero without the
  // instrument's strings or in silence).
  int Analyze(const float* x,
              std::array<PolyNote, 2>* notes,
              std::array<std::array<PolyNote, 2>, kStringPairs>* on_strings = nullptr);

 private:
  struct Best {
    int index = -1;
    double salience = 0;
  };
  double Salience(int candidate, const std::vector<double>& spectrum) const;
  // The fundamental's magnitude (BandMax of partial 1) when it is a local maximum of the
  // spectrum; 0 when the band only holds the slope of a peak outside it.
  double Fundamental(int candidate, const std::vector<double>& spectrum) const;
  double BandMax(int candidate, int m, const std::vector<double>& spectrum, int* at) const;
  Best Search(const std::vector<double>& spectrum, int first) const;
  double Refine(int candidate, const std::vector<double>& spectrum);
  double Cancel(int candidate);
  int LostFundamental(int note, int partner);
  int PartialFifth(int low, int high) const;
  int FreePair(std::array<PolyNote, 2>* notes);
  std::array<PolyNote, 2> PairOnStrings(int lower_string_low_to_high);
  double Explained(int candidate, const std::vector<double>& spectrum) const;

  DoubleStopOptions options_;
  int window_ = 0, fft_size_ = 0, lobe_bins_ = 0;
  double bin_hz_ = 0, floor_ = 0;
  std::array<double, 4> open_midi_{};
  bool has_strings_ = false;
  std::vector<double> candidates_hz_, candidates_midi_, hann_;
  std::vector<std::array<int, 2>> bands_;  // [candidate * M + m - 1]: bins lo, hi (-1: none)
  std::vector<double> magnitude_, residual_;
  // Per-partial scratch of Refine and Cancel (sized once: no allocation per frame).
  std::vector<double> partial_hz_, partial_amplitude_;
  std::vector<int> partial_index_;
  double* time_ = nullptr;
  void* spectrum_ = nullptr;
  void* plan_ = nullptr;
};

// Pairs made consistent over time (issue 27; docs/audio.md, "Double stops"). A frame's
// analysis alone can take a pair's partials for the pair: a viola's E3 + G#3 heard as
// G#4 + B4 (the upper note's 2nd partial and the lower's 3rd) or as G#3 + E4, an octave
// E3 + E4 as E4 + B4, alternating frame by frame while the notes sound. A pair of frame i
// is replaced by another pair K found on frames on both sides of it (within window_frames
// before and after) when every note of frame i's pair is one of K's notes or its 2nd, 3rd
// or 4th partial (within half a semitone): the simpler explanation the neighbours confirm.
// Among such K, the one on most frames of the window (then the lowest); its f0s and
// saliences are those of its nearest frame (the earlier on a tie). K must be on at least
// half as many frames of the window as frame i's own pair: a chord's short lower pair
// D4 + A4 heard right on 6 of its 8 frames and as A3 + D4 at its two onsets stays D4 + A4. Frames
// with fewer than two notes are left as they are; decisions are made on the input, so the order of
// frames plays no part. window_frames 0: unchanged.
void ConsistentDoubleStops(int window_frames, std::vector<PolyPitchFrame>* frames);

// The second note beside the single-note tracker's f0, one per tracker frame (poly[i] must
// be frame i at the same time; rows past the end of `poly` get 0): when frame i has two
// notes and one lies within match_cents of the tracker's voiced f0, the other's f0; else 0
// (the tracker's f0 stays what it was).
std::vector<double> SecondNoteHz(const std::vector<PitchFrame>& frames,
                                 const std::vector<PolyPitchFrame>& poly,
                                 double match_cents = 50.0);

// Notes of the second voice: SegmentNotes on the frames with f0 = second_f0_hz (voiced
// where > 0) at `fps`. Merged with the first voice's notes by onset they overlap them
// (notes.csv holds overlapping notes: its rows are only sorted by onset).
NoteAnalysis SecondVoiceNotes(const std::vector<PitchFrame>& frames,
                              const std::vector<double>& second_f0_hz,
                              double fps,
                              const NoteOptions& options);

// Frames at start_s + i / fps (the tracker's video rows) from an open reader.
StatusOr<std::vector<PolyPitchFrame>> TrackDoubleStops(std::unique_ptr<AudioReader> reader,
                                                       const DoubleStopOptions& options,
                                                       DoubleStopSummary* summary);
StatusOr<std::vector<PolyPitchFrame>> TrackDoubleStopsFile(const std::string& path,
                                                           const DoubleStopOptions& options,
                                                           DoubleStopSummary* summary);

}  // namespace arco::audio
