// The terminal's text for the library's results (the library itself never prints):
// `arco run`'s stage lines, `arco run` / `arco refine`'s method lines and
// `arco triangulate --view`'s point table.
#pragma once

#include <string>

#include "arco/pipeline/run_capture.h"
#include "arco/refine/refine.h"
#include "arco/util/json_io.h"

namespace arco::cli {

// One line per method: pressed/open/rest/uncertain frames, corrected frames and the
// fingertip-to-contact distance before and after.
std::string FormatRefineSummary(const refine::RefineSummary& summary);

// The one-line summary of a stage of `arco run` (timing.name: triangulate, instrument,
// hands, pitch, refine).
std::string FormatStageLine(const pipeline::RunSummary& summary,
                            const pipeline::StageTiming& timing);

// Human-readable report of capture::TriangulateLabelViews' JSON.
std::string FormatLabelViewsReport(const Json& result);

}  // namespace arco::cli
