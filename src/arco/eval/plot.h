// A self-contained SVG of an evaluation (no plotting library): the truth and
// estimated pitch over time, and per method the left-hand error and the contact
// deviation per frame (docs/evaluation.md).
#pragma once

#include <string>
#include <vector>

#include "arco/eval/evaluate.h"

namespace arco::eval {

// `fps` converts frames to seconds on the time axis.
std::string EvalPlotSvg(const EvalReport& report, double fps);

}  // namespace arco::eval
