// The terminal text of `arco pitch` and `arco sync`: what was read, tracked and written,
// and the library's warnings with its field names mapped to the command's flags.
#pragma once

#include <string>
#include <vector>

#include "arco/capture/pitch_sync.h"

namespace arco::cli {

std::string FormatPitchReport(const capture::PitchRunOptions& options,
                              const capture::PitchRunResult& result);
std::string FormatSyncReport(const capture::SyncRunOptions& options,
                             const capture::SyncRunResult& result);
// Their warnings (for stderr: PrintWarning), the fields named by the command's flags.
std::vector<std::string> PitchWarnings(const capture::PitchRunResult& result);
std::vector<std::string> SyncWarnings(const capture::SyncRunResult& result);

}  // namespace arco::cli
