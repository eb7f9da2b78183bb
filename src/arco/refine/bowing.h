// The bow arm read from the tracked bow and the strings (docs/bowing.md): per frame the
// string under the bow, bow direction and speed, sounding point, position on the bow,
// inclination and skew, bow changes; per note the same summarised and checked against
// the refinement's fingered string and the audio's onsets.
//
// Geometry. The bow is the line through its frog and tip points (SPD's lie on the stick,
// 10-25 mm above the hair: the line's direction is the hair's within about a degree, its
// distance to the strings is not). The instrument frame comes from the frame's strings
// (instrument/strings.h: x bridge -> nut, y toward the low string, z to the front). The
// string under the bow is read from the bow's inclination across the strings, the one
// quantity the stick offset does not disturb: a bow on one string is tangent to the
// bridge's arch there (InstrumentModel::BowInclinationRad), so the nearest string
// inclination wins, and an inclination near the midpoint of two neighbours touches both
// (a double stop). The nearest-string distance, which the stick offset spoils, only says
// whether the bow is off the strings altogether (`max_lift_mm`).
//
// Motion. The contact's place along the bow (mm from the frog) over time: its rate is the
// bow speed, positive for a down-bow (the contact moves from the frog toward the tip, the
// bow is drawn toward the performer's right). Bow changes are its turning points, each
// confirmed once the bow has gone back `min_stroke_mm` (a zigzag filter: jitter and a slow
// bow's wobble are no change), located between frames where the two straight strokes
// around it meet; each frame on a string takes its stroke's direction where the bow moves.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "arco/instrument/instrument_model.h"
#include "arco/instrument/strings.h"
#include "arco/refine/contact_annotation.h"
#include "arco/util/json_io.h"
#include "arco/util/number_range.h"
#include "arco/util/status.h"

namespace arco::refine {

inline constexpr NumberRange kBowMinSpeedRangeMmPerS = Closed(0, 1000);
inline constexpr NumberRange kBowMaxLiftRangeMm = AboveZero(500);
inline constexpr NumberRange kBowMinStrokeRangeMm = AboveZero(500);
inline constexpr NumberRange kBowDoubleStopMarginRangeDeg = Closed(0, 20);
inline constexpr NumberRange kBowOnsetToleranceRangeS = AboveZero(1);

struct BowingOptions {
  // Slower than this the bow is still: no direction (unless at a bow change).
  double min_speed_mm_per_s = 50;
  // A bow change is confirmed once the bow has gone back this far from the turning point:
  // smaller reversals are the points' jitter or a slow bow's wobble.
  double min_stroke_mm = 20;
  // A bow line farther than this from the string it is inclined to is off the strings.
  // SPD's stick points lie up to 26 mm from the string they play (docs/bowing.md).
  double max_lift_mm = 30;
  // An inclination within this of the midpoint between two neighbouring strings' touches
  // both (a double stop).
  double double_stop_margin_deg = 3;
  // A bow change this close to an audio onset "coincides" with it.
  double onset_tolerance_s = 0.1;
  Status Validate() const;
};

enum class BowDirection { kNone = 0, kDown = 1, kUp = -1 };
const char* BowDirectionName(BowDirection d);  // "none", "down", "up"

struct BowingFrame {
  double time_s = 0;
  bool seen = false;      // bow and strings known in this frame
  int string = 0;         // under the bow (1 = highest); 0 = off the strings or not seen
  int second_string = 0;  // the neighbour a double stop also touches, else 0
  double inclination_deg = kNaN;  // across the strings, from the string plane (see above)
  double skew_deg = kNaN;         // bow against the bridge line, + tip toward the nut
  double lift_mm = kNaN;          // bow line to the string (the stick's offset included)
  double sounding_point_mm = kNaN;  // contact to the bridge along the string
  double bow_position = kNaN;       // contact on the bow: 0 frog, 1 tip
  double bow_speed_mm_per_s = kNaN;  // signed: + down-bow
  BowDirection direction = BowDirection::kNone;
  bool bow_change = false;  // the first frame after a bow change
};

struct BowingNote {
  int note = 0;  // NoteFingering::note
  double onset_s = 0, duration_s = 0;
  int fingered_string = 0;  // the refinement's (NoteFingering::string; 0 = none)
  int bow_string = 0;       // most frames' string under the bow (0 = off)
  int bow_second_string = 0;
  bool strings_agree = true;  // false: the bow is on another string than the fingered one
  BowDirection direction = BowDirection::kNone;  // most frames'
  double mean_speed_mm_per_s = kNaN;
  double sounding_point_mm = kNaN;  // median
  double bow_from = kNaN, bow_to = kNaN;  // bow position at its first and last frame
  double change_to_onset_s = kNaN;  // nearest bow change minus the onset
};

struct BowingSummary {
  int frames = 0, frames_seen = 0, frames_on_string = 0;
  int bow_changes = 0;
  int bow_changes_at_onsets = 0;  // within onset_tolerance_s of a note onset
  int notes = 0;
  int notes_string_disagree = 0;
  double median_sounding_point_mm = kNaN;
  double median_speed_mm_per_s = kNaN;  // of moving frames
};

struct BowingResult {
  std::vector<BowingFrame> frames;
  std::vector<BowingNote> notes;
  std::vector<double> change_times_s;
  BowingSummary summary;
};

struct BowingInput {
  std::vector<Eigen::Vector3d> frog_in_world_mm, tip_in_world_mm;  // NaN: not seen
  std::vector<std::vector<StringSegment>> strings_in_world_mm;       // empty: no pose
  std::vector<NoteFingering> notes;  // the refinement's notes (onsets, fingered strings)
  double fps = 30;
  double start_s = 0;  // time of frame 0
};

// Throws nothing; an invalid `options` or mismatched input sizes are an error status.
// AnalyzeBowStrokes then AddBowingNotes with input.notes.
StatusOr<BowingResult> AnalyzeBowing(const InstrumentModel& instrument,
                                     const BowingInput& input,
                                     const BowingOptions& options);
// The per-frame part, which does not depend on the notes: frames, changes and the summary
// but for its notes, notes_string_disagree and bow_changes_at_onsets (0); input.notes is
// not read. A refinement that needs the bow before its notes are final analyses it once.
StatusOr<BowingResult> AnalyzeBowStrokes(const InstrumentModel& instrument,
                                         const BowingInput& input,
                                         const BowingOptions& options);
// The per-note part on `result` (AnalyzeBowStrokes'): its notes and their counts in the
// summary, replacing any from an earlier call.
void AddBowingNotes(const std::vector<NoteFingering>& notes,
                    const BowingOptions& options,
                    BowingResult* result);

Json ToJson(const BowingSummary& summary);
Json ToJson(const BowingOptions& options);

// RESULT/arco/bowing.csv (per frame) and bowing_notes.csv (per note); docs/formats.md.
inline constexpr const char* kBowingCsvHeader =
    "frame,time_s,string,second_string,inclination_deg,skew_deg,lift_mm,sounding_point_mm,"
    "bow_position,bow_speed_mm_per_s,direction,bow_change";
inline constexpr const char* kBowingNotesCsvHeader =
    "note,onset_s,duration_s,fingered_string,bow_string,bow_second_string,strings_agree,"
    "direction,mean_speed_mm_per_s,sounding_point_mm,bow_from,bow_to,change_to_onset_s";
Status WriteBowingCsv(const std::string& path, const std::vector<BowingFrame>& frames);
Status WriteBowingNotesCsv(const std::string& path, const std::vector<BowingNote>& notes);
// Reads bowing.csv (arco's or a truth folder's: the columns frame, string, direction,
// sounding_point_mm are required, the others optional); errors name the file and line.
StatusOr<std::vector<BowingFrame>> ReadBowingCsv(const std::string& path);
// Reads bowing_notes.csv (every column); errors name the file and line.
StatusOr<std::vector<BowingNote>> ReadBowingNotesCsv(const std::string& path);

}  // namespace arco::refine
