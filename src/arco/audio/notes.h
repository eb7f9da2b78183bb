// Notes, vibrato and glides from a fine pitch track.
//
// Pitch is handled in semitones s = 69 + 12 log2(f0 / a4_hz) (MIDI numbers with
// a fractional part). Segmentation: voiced runs (gaps up to max_gap_s bridged)
// are smoothed with a moving median (about one vibrato period, so vibrato does
// not split notes); frames where the smoothed pitch moves faster than
// glide_slope_semitones_per_s for at least min_glide_s and min_glide_semitones
// form glides; the rest is split where the smoothed pitch leaves the running
// note centre by more than split_semitones for min_note_s. Vibrato: the note's
// pitch minus a straight-line fit (intonation drift), then the autocorrelation
// peak between 1/max_rate and 1/min_rate gives the rate, sqrt(2) x RMS the
// extent (the +- amplitude in cents of a sinusoidal vibrato).
#pragma once

#include <string>
#include <vector>

#include "arco/audio/midi_file.h"
#include "arco/audio/pitch_tracker.h"
#include "arco/util/status.h"

namespace arco::audio {

struct NoteOptions {
  double a4_hz = 440.0;
  double min_note_s = 0.06;
  double max_gap_s = 0.03;       // unvoiced gaps bridged inside a note
  double smoothing_s = 0.15;     // moving-median window
  double split_semitones = 0.7;  // hysteresis for a new note
  double glide_slope_semitones_per_s = 8.0;
  double min_glide_s = 0.05;
  double min_glide_semitones = 0.8;
  double vibrato_min_rate_hz = 3.0;
  double vibrato_max_rate_hz = 10.0;
  double vibrato_min_extent_cents = 8.0;
  double vibrato_min_correlation = 0.5;  // autocorrelation peak (periodicity)
  Status Validate() const;
};

struct Note {
  double onset_s = 0, offset_s = 0;
  double median_f0_hz = 0;
  int midi_note = 0;           // nearest equal-tempered note at a4_hz
  double cents_from_et = 0;    // median pitch minus that note, cents
  double vibrato_rate_hz = 0;  // 0: no vibrato detected
  double vibrato_extent_cents = 0;
};

struct Glide {
  double start_s = 0, end_s = 0;
  double start_f0_hz = 0, end_f0_hz = 0;
};

struct NoteAnalysis {
  std::vector<Note> notes;
  std::vector<Glide> glides;
};

// `fine` rows at `fine_fps` (PitchTrack::fine). Throws std::invalid_argument on
// invalid options (call Validate first for a Status).
NoteAnalysis SegmentNotes(const std::vector<PitchFrame>& fine,
                          double fine_fps,
                          const NoteOptions& options);

// A one-track MIDI file of the notes: note on/off at onset/offset and pitch
// bends following the fine track inside each note (a bend whenever the pitch
// moved by >= 1 cent, range bend_range_semitones).
MidiFile NotesToMidi(const NoteAnalysis& analysis,
                     const std::vector<PitchFrame>& fine,
                     const NoteOptions& options,
                     int gm_program,
                     double bend_range_semitones = 2.0);

// GM program (registry/instruments.h) for any name ParseInstrumentKind accepts: violin 40,
// viola 41, cello 42, double bass 43; "any" and unknown names get the cello's.
int GmProgramForInstrument(const std::string& instrument);

// "C2", "F#4", ... for a MIDI note number.
std::string NoteName(int midi_note);

// notes.csv: kind (note|glide), onset_s, offset_s, median_f0_hz, midi_note,
// note_name, cents_from_et, vibrato_rate_hz, vibrato_extent_cents, start_f0_hz,
// end_f0_hz; rows sorted by onset. Written atomically.
inline constexpr char kNotesCsvHeader[] =
    "kind,onset_s,offset_s,median_f0_hz,midi_note,note_name,cents_from_et,vibrato_rate_hz,"
    "vibrato_extent_cents,start_f0_hz,end_f0_hz";
Status WriteNotesCsv(const std::string& path, const NoteAnalysis& analysis);
// The file's text.
std::string FormatNotesCsv(const NoteAnalysis& analysis);
// The note rows of a notes.csv: onset_s, offset_s and median_f0_hz (the other columns and
// the glides are not read back). The header must start with those columns. Errors name the
// file and line: a malformed number, offset before onset, a non-positive pitch, onsets out
// of order.
StatusOr<std::vector<Note>> ReadNotesCsv(const std::string& path);
// The same on the file's text; `source` names it in messages (ParseNotesCsv(
// FormatNotesCsv(analysis)): the notes as a reader of the file gets them).
StatusOr<std::vector<Note>> ParseNotesCsv(const std::string& text, const std::string& source);

}  // namespace arco::audio
