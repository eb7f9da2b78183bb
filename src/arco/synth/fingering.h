// Fingering planner: for every note of a monophonic score, choose the string,
// the finger (0 = open string, 1 = index .. 4 = little) and the hand position,
// the way a string player would, by dynamic programming (Viterbi) over the note
// sequence. Documented in docs/synth.md.
//
// Hand position: `position_semitones` is where finger 1 would stop the string,
// in semitones above the open string (1 = half position, 2 = cello/violin first
// position, ...). Because adjacent strings are tuned a fifth apart, one hand
// position covers the same semitone offsets on every string. A finger f in a
// position p stops semitone p + offset(f), with the offsets of the instrument's
// hand frame (FingerSpans): cello closed position 0/1/2/3 (1st..4th finger a
// semitone apart), cello extension 0/2/3/4; violin/viola 0, 1-2, 3-4, 5;
// double bass (Simandl) 0/1/2 with fingers 1, 2, 4.
//
// Cost of a plan = sum over notes of a note cost + sum over consecutive notes of
// a transition cost (see FingeringOptions for each term). Ties are broken towards
// the lower string, lower finger and lower position, so plans are deterministic.
#pragma once

#include <string>
#include <vector>

#include "arco/registry/instruments.h"
#include "arco/synth/score.h"
#include "arco/util/status.h"

namespace arco::synth {

struct FingeringOptions {
  int max_position_semitones = 17;    // highest hand position considered
  double position_cost = 0.12;        // per semitone of hand position (prefer low positions)
  double shift_cost = 2.0;            // per change of hand position
  double shift_distance_cost = 0.25;  // per semitone shifted
  double free_shift_factor = 0.3;     // shift costs scale when the shift happens on an
                                      // open string or in a rest >= rest_s
  double rest_s = 0.4;                // a gap this long frees the hand
  double fast_note_s = 0.2;           // shifting between notes closer than this ...
  double fast_shift_factor = 2.0;     // ... multiplies the shift cost by this
  double string_crossing_cost = 0.3;  // per string crossed
  double extension_cost = 0.8;        // extended hand frame (cello 1-4 spans a major third)
  double open_string_cost = 0.3;      // playing a short note on an open string
  double open_long_note_cost = 4.0;   // an open string for a note >= long_note_s (no vibrato)
  double long_note_s = 0.8;
  double fourth_finger_cost = 0.2;  // mild preference for fingers 1-3

  Status Validate() const;
};

// The hand frame (registry/instruments.h, FingerSpan) of an instrument name
// (ParseInstrumentKind); unknown names throw std::invalid_argument.
const std::vector<FingerSpan>& HandFrameFor(const std::string& instrument_name);

struct NoteFingering {
  int string_index = 0;        // 0 = lowest string (cello C, violin G)
  int finger = 0;              // 0 = open string, 1..4
  int position_semitones = 0;  // hand position (finger 1's semitone); kept through open strings
  int semitone_on_string = 0;  // midi_note - open string's midi note
  bool extended = false;
  // The upper note of a double stop (ScoreNote::second_midi_note): on the next higher
  // string, string_index + 1, in the same hand position (and frame); -1 on a single note.
  // Two stopped notes take two fingers, except a fifth, which one finger stops across
  // both strings (second_finger == finger).
  int second_string_index = -1;
  int second_finger = 0;  // 0 = open string
  int second_semitone_on_string = 0;
  bool IsDoubleStop() const { return second_string_index >= 0; }
};

struct FingeringPlan {
  std::vector<NoteFingering> notes;  // one per score note
  double total_cost = 0;
  int num_shifts = 0;
  int num_open_strings = 0;
  int num_string_crossings = 0;
};

// Plans the whole score. A chord's upper pair (ScoreNote::chord_upper_pair) keeps its lower
// pair's hand position and continues its strings, with every finger of the chord held down
// together. Errors when a note (or double stop, or chord) cannot be played on any string
// (pair).
StatusOr<FingeringPlan> PlanFingering(const Score& score,
                                      const ScoreInstrument& instrument,
                                      const FingeringOptions& options = {});

}  // namespace arco::synth
