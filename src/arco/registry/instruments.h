// The instruments arco knows, in one table: names (and the aliases the parser accepts),
// open strings, General MIDI program, the SPD keypoint layout, the pitch tracker's
// search range, and the left hand's finger frame. Every layer that needs one of these
// (audio, instrument, synth, refine, eval, the CLI) looks it up here; the physical
// setup (string length, spacings, heights) is the instrument model's
// (instrument/instrument_model.h).
//
// Strings here are listed LOW to high (open_midi_low_to_high[0] is the cello's C); the
// instrument model numbers strings from the highest (string 1), see instrument_model.h.
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "arco/util/number_range.h"
#include "arco/util/status.h"

namespace arco {

// The concert pitch every A4 (tuning reference) must lie in: the pitch tracker's, the
// notes', the synthesis', the instrument models', capture.json's tuning and the CLI's --a4
// flags all check this one range. French baroque 392 Hz, baroque 415, modern 440-446,
// with a margin on both sides.
inline constexpr NumberRange kA4RangeHz = Closed(300, 600);
// A string's tuning offset from standard (scordatura), cents: within two octaves.
inline constexpr NumberRange kTuningOffsetRangeCents = Closed(-2400, 2400);

enum class InstrumentKind { kViolin, kViola, kCello, kDoubleBass };

// One place a finger can stop in the left hand's frame: finger `finger` (1 = index ..
// 4 = little) stops offset_semitones above finger 1; `extended` marks a stretched frame
// (cello 1-4 over a major third). Used by the fingering planner (synth/fingering.h).
struct FingerSpan {
  int finger = 1;
  int offset_semitones = 0;
  bool extended = false;
};

// Search range and analysis rate of the pitch tracker for an instrument
// (audio/pitch_tracker.h): the lowest open string minus about a semitone and a half;
// the top leaves room for high positions and harmonics (violin above E7 = 2637 Hz).
// Analysis rates keep the shortest period >= 6 samples and the harmonics that matter
// below Nyquist.
struct PitchSearchRange {
  double min_f0_hz = 0;
  double max_f0_hz = 0;
  int analysis_rate_hz = 0;
};

struct InstrumentInfo {
  InstrumentKind kind;
  const char* name;  // canonical: "violin", "viola", "cello", "double_bass"
  std::array<int, 4> open_midi_low_to_high;
  std::array<const char*, 4> open_notes_low_to_high;  // "C2", ...
  int gm_program;                                     // General MIDI program, 0-based
  const char* spd_layout;  // keypoint layout of SPD's instrument points (registry)
  PitchSearchRange pitch_search;
  // The hand frame (FingerSpan): cello closed 0/1/2/3 and extended 0/2/3/4; violin and
  // viola 0, 1-2, 3-4, 5 (6 stretched); double bass (Simandl) fingers 1, 2, 4 at 0/1/2.
  std::vector<FingerSpan> hand_frame;
  // Whether the hand frame's spacing holds in mm up the neck (cello, double bass: low on
  // the neck one finger per semitone, widening to a scale step per finger in the upper and
  // thumb positions, where a semitone is half as long) rather than in semitones (violin,
  // viola: the fingers close up with the semitones and keep their intervals).
  bool frame_spacing_in_mm = false;
};

// Every instrument, in InstrumentKind order.
const std::vector<InstrumentInfo>& AllInstruments();
const InstrumentInfo& GetInstrumentInfo(InstrumentKind kind);

// The one instrument-name parser. Accepts the canonical names "violin", "viola", "cello",
// "double_bass", and the aliases "violoncello", "double-bass", "doublebass", "bass",
// "contrabass"; case-insensitive. Unknown names: an error listing the canonical ones.
StatusOr<InstrumentKind> ParseInstrumentKind(std::string_view name);
// The canonical name ("violin", "viola", "cello", "double_bass").
const char* InstrumentKindName(InstrumentKind kind);

// Semitones from finger 1's stop to finger `finger`'s in the instrument's closed hand
// frame, derived from hand_frame: the largest non-extended offset of that finger (violin
// 0/2/4/5, cello 0/1/2/3); a finger the frame does not use on its own stops with the next
// higher one (double bass finger 3 with finger 4: 0/1/2/2). Finger 0 (open) is 0; fingers
// outside 0..4 are clamped.
double FingerOffsetSemitones(InstrumentKind kind, int finger);
// Finger 1's place (semitones above the open string) when finger `finger` stops the string
// `stop_semitones` above it: stop_semitones - FingerOffsetSemitones, or, where
// frame_spacing_in_mm, finger 1 the frame's offset in mm below the stop, the mm of the first
// position (finger 1 a whole tone above the open string; with l = 2^(-s/12) the stop's
// remaining fraction of the string, finger 1 is at l + 2^(-2/12) - 2^(-(2+o)/12)). The two
// agree in the first position; on the cello's A string, finger 3 a whole tone above
// finger 2 at 311 mm from the nut (SPD cello01) is one semitone of offset in semitones and
// 1.7 in mm.
double HandPositionSemitones(InstrumentKind kind, int finger, double stop_semitones);
// Every offset from finger 1's stop that finger `finger` reaches: first
// FingerOffsetSemitones, then the other closed-frame reaches, largest first (violin and
// viola finger 2: 2, 1; finger 3: 4, 3), then the extended ones (cello extension, the
// violin's stretched 4th). Finger 0 (open): one reach of 0.
std::vector<FingerSpan> FingerReaches(InstrumentKind kind, int finger);

}  // namespace arco
