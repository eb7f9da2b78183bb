// Scores for synthetic performances: what notes are played and when.
//
// A Score is a list of notes (MIDI numbers, onset/offset in seconds), one at a time; a
// note may carry a second, higher note sounding with it (a double stop on two adjacent
// strings, ScoreNote::second_midi_note). A 3- or 4-note chord is two such double stops
// in a row, rolled as on a bowed string (ScoreNote::chord_upper_pair).
// Built-in pieces are generated per instrument from its open strings, so the same
// piece name gives a sensible part on cello, violin, viola or double bass. Scores
// can also be read from a Standard MIDI File (midi_reader.h).
//
// Conventions: MIDI note 69 = A4; times are seconds from the start of the
// performance; notes are sorted by onset and never overlap (offset <= next onset).
#pragma once

#include <string>
#include <vector>

#include "arco/util/status.h"

namespace arco::synth {

// What the score and the fingering planner need to know about an instrument.
// Filled from the instrument model (see synth_instrument.h); kept minimal so the
// score layer is testable on its own.
struct ScoreInstrument {
  std::string name;                   // "cello", "violin", ...
  std::vector<int> open_string_midi;  // lowest string first
  int max_semitones_above_open = 24;  // playable range per string (two octaves)
  int gm_program = 42;                // General MIDI program (0-based: 42 = cello)
  // Widest distance between two stopped fingers in one closed hand frame (semitones:
  // violin 5, cello 3, double bass 2); the double-stops piece keeps within it.
  int hand_span_semitones = 3;

  int LowestMidi() const;
  int HighestMidi() const;
  // True when some string can sound `midi_note`.
  bool InRange(int midi_note) const;
};

struct ScoreNote {
  int midi_note = 60;
  double onset_s = 0;
  double offset_s = 0;
  int velocity = 80;  // 1..127
  // The upper note of a double stop, played on the next higher string with the same
  // onset and offset; 0: a single note.
  int second_midi_note = 0;
  // The upper pair of a 3- or 4-note chord, rolled 2+2: the bow sounds at most two
  // adjacent strings, so the previous note (a double stop) is the chord's lower pair,
  // sounding briefly, and this pair is held. The left hand stops all the chord's notes at
  // once: this pair's lower note lies on the previous pair's upper string when they share
  // it (a 3-note chord, midi_note == previous second_midi_note), else on the next string
  // up (a 4-note chord), in the same hand position (synth/fingering.h).
  bool chord_upper_pair = false;
  bool IsDoubleStop() const { return second_midi_note > 0; }
};

struct Score {
  std::string name;  // piece name or MIDI file name
  std::vector<ScoreNote> notes;
  double duration_s = 0;  // end of the last note plus a short release
};

// Names of the built-in pieces, in the order `arco synth --help` lists them.
const std::vector<std::string>& BuiltInPieceNames();
// The built-in pieces' names, comma-separated (for messages).
std::string BuiltInPieceList();
// Ok for a built-in piece's name; else "piece 'NAME' is unknown (built-in pieces: ...)".
Status CheckBuiltInPieceName(const std::string& name);

// One-line description of a built-in piece (for --help and docs).
std::string DescribeBuiltInPiece(const std::string& name);

// Generates a built-in piece for an instrument. `tempo_scale` > 1 plays slower
// (all durations multiplied). Unknown names return an error listing the names.
StatusOr<Score> MakeBuiltInPiece(const std::string& name,
                                 const ScoreInstrument& instrument,
                                 double tempo_scale = 1.0);

// Checks ordering, positive durations, no overlap, that every note (and every double
// stop's second note, above the first) is in the instrument's range, and that a chord's
// upper pair is a double stop following its lower pair, at or above that pair's upper
// note; the error names the first
// offending note ("note 30 (F#1) at 2.500 s is below the cello's lowest note C2 (36)"). `source`
// prefixes it.
Status ValidateScore(const Score& score,
                     const ScoreInstrument& instrument,
                     const std::string& source);

// Keeps only the notes that start before `max_duration_s` (clipping the last),
// so a long piece can be shortened for a demo. No-op when <= 0.
Score TruncateScore(const Score& score, double max_duration_s);

// "C4", "F#1", "A#5": scientific pitch name with sharps (MIDI 60 = C4).
std::string MidiNoteName(int midi_note);

// Frequency of a MIDI note plus a deviation in cents, given A4.
double MidiToHz(double midi_note, double a4_hz = 440.0);

}  // namespace arco::synth
