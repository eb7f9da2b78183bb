// Standard MIDI File (SMF format 1) writing, with pitch bends, and a small
// reader for checking what was written. A reusable API: `arco pitch --midi`
// exports notes with it, and the synthesis layer renders test music from it
// (fluidsynth).
//
// Times are seconds; the file uses a fixed tempo (us_per_quarter) and
// ticks_per_quarter, so tick = round(time_s * 1e6 / us_per_quarter * tpq).
// Each track gets its own channel, a program change, and RPN 0 (pitch-bend
// sensitivity) set to bend_range_semitones; bends are in semitones relative to
// the sounding note and clamped to that range (14-bit, centre 8192).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "arco/util/status.h"

namespace arco::audio {

struct MidiNote {
  double onset_s = 0, offset_s = 0;
  int midi_note = 60;  // 0..127
  int velocity = 80;   // 1..127
};

struct MidiPitchBend {
  double time_s = 0;
  double semitones = 0;  // relative to the note; 0 = centre
};

struct MidiControl {
  double time_s = 0;
  int controller = 0;  // 0..127, e.g. 7 volume, 64 sustain, 120 all sound off
  int value = 0;       // 0..127
};

struct MidiTrack {
  std::string name;
  int channel = 0;  // 0..15 (9 is GM percussion)
  int program = 0;  // GM program 0..127 (42 cello, 40 violin, 41 viola, 43 contrabass)
  std::vector<MidiNote> notes;
  std::vector<MidiPitchBend> bends;
  std::vector<MidiControl> controls;  // sent before notes starting at the same tick
};

struct MidiFile {
  int ticks_per_quarter = 960;
  int us_per_quarter = 500000;  // 120 bpm: 1920 ticks per second
  double bend_range_semitones = 2.0;
  std::vector<MidiTrack> tracks;
};

// Bytes of the file; std::invalid_argument on out-of-range fields.
std::string EncodeMidi(const MidiFile& file);
Status WriteMidiFile(const std::string& path, const MidiFile& file);

// One channel event read back (tests): status high nibble, channel, data bytes.
struct MidiEvent {
  int64_t tick = 0;
  int track = 0;
  int type = 0;  // 0x80 note off, 0x90 note on, 0xB0 control, 0xC0 program, 0xE0 bend
  int channel = 0;
  int data1 = 0, data2 = 0;
};
struct ParsedMidi {
  int format = 0;
  int ticks_per_quarter = 0;
  int us_per_quarter = 500000;
  std::vector<MidiEvent> events;  // all tracks, in file order per track
};
// Parses an SMF (format 0 or 1) with running status; errors on malformed data.
StatusOr<ParsedMidi> ParseMidi(const std::string& bytes);

}  // namespace arco::audio
