// A small Standard MIDI File reader (SMF format 0 and 1, PPQ or SMPTE time
// division, running status, tempo changes in any track) that turns the note
// events into a monophonic Score for `arco synth --midi`.
//
// Rules (documented in docs/synth.md):
//   - channel 10 (drums, index 9) is ignored; all other channels are merged;
//   - notes that start within 5 ms of each other are a chord: an error, since the
//     synthetic performer plays one note at a time (double stops are out of scope);
//   - a note that is still sounding when the next starts is cut at that onset
//     (overlapping legato is common in MIDI exports);
//   - a note-on without note-off ends at the end of its track;
//   - pitch bends, controllers and programs in the file are ignored: arco synth
//     writes its own expression (vibrato, intonation) into the rendered MIDI.
#pragma once

#include <string>

#include "arco/synth/score.h"
#include "arco/util/status.h"

namespace arco::synth {

// Parses SMF bytes; `source` names the file in error messages. The notes are not
// range-checked here (see ValidateScore).
StatusOr<Score> ParseMidiScore(const std::string& bytes, const std::string& source);

// Reads a file and checks every note against the instrument's range; the error
// names the offending note, e.g. "tune.mid: note 30 (F#1) at 2.500 s is outside
// the cello's range C2 (36) to A5 (81)".
StatusOr<Score> ReadMidiScore(const std::string& path, const ScoreInstrument& instrument);

}  // namespace arco::synth
