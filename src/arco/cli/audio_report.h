// The terminal text of `arco pitch` and `arco sync`: what was read, tracked and written,
// and the library's warnings with its field names mapped to the command's flags.
#pragma once

#include <string>
#include <vector>

#include "arco/pipeline/pitch_sync.h"

namespace arco::cli {

std::string FormatPitchReport(const pipeline::PitchRunOptions& options,
                              const pipeline::PitchRunResult& result);
std::string FormatSyncReport(const pipeline::SyncRunOptions& options,
                             const pipeline::SyncRunResult& result);
// Their warnings (for stderr: PrintWarning), the fields named by the command's flags.
std::vector<std::string> PitchWarnings(const pipeline::PitchRunResult& result);
std::vector<std::string> SyncWarnings(const pipeline::SyncRunResult& result);

}  // namespace arco::cli
