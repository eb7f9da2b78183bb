// "FIRST:LAST" frame ranges on the command line (`arco detect --frames`,
// `arco overlay --frames`): whole frame numbers, either side may be empty (open).
#pragma once

#include <cstdint>
#include <string>

#include "arco/util/status.h"

namespace arco::cli {

// Parses `text` into `first`/`last`; an empty text or side leaves that value as it was.
// Checking the numbers against the capture or result is the stage's job.
Status ParseFrameRange(const std::string& text, int64_t* first, int64_t* last);

}  // namespace arco::cli
