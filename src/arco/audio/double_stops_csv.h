// double_stops.csv: the polyphonic tracker's frames (double_stops.h, TrackDoubleStops) as
// `arco run --double-stops` hands them to the refinement, kept in the result folder so that
// `arco refine` refines the same two voices (docs/formats.md). Header
// `frame,time_s,notes,f0_low_hz,f0_high_hz`: one row per video frame from 0, `notes` the
// count found (0, 1 or 2), f0_low_hz the lower (or only) note and f0_high_hz the upper, in
// Hz to 1e-4, 0 where there is none; then, for s = 1, 2, 3 (1 = highest),
// `on_S_low_hz,on_S_high_hz`: the pair heard as played on strings s and s + 1
// (PolyPitchFrame::on_strings), both 0 where none. The notes' saliences are not kept. A
// file without the on_ columns (written before them) reads with those pairs 0.
#pragma once

#include <string>
#include <vector>

#include "arco/audio/double_stops.h"
#include "arco/util/status.h"

namespace arco::audio {

inline constexpr char kDoubleStopsCsvHeader[] =
    "frame,time_s,notes,f0_low_hz,f0_high_hz,on_1_low_hz,on_1_high_hz,on_2_low_hz,on_2_high_hz,"
    "on_3_low_hz,on_3_high_hz";

std::string FormatDoubleStopsCsv(const std::vector<PolyPitchFrame>& frames);
// `source` names the text in messages. Errors: a missing column, a cell that is not a
// finite number, a frame out of order, a count outside 0-2, f0s that do not match the
// count (0 < f0_low_hz <= f0_high_hz for two notes, f0_high_hz 0 for one, both 0 for none),
// an on_ pair with one f0 0 and not the other or its low above its high.
StatusOr<std::vector<PolyPitchFrame>> ParseDoubleStopsCsv(const std::string& text,
                                                          const std::string& source);
StatusOr<std::vector<PolyPitchFrame>> ReadDoubleStopsCsv(const std::string& path);

}  // namespace arco::audio
