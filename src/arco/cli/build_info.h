// What this arco was built from, for `arco --version` and `arco info`. The definitions are
// generated at every build (cmake/write_build_info.cmake), so the revision is the one
// actually compiled, not the one at configure time.
#pragma once

#include <string>

namespace arco::cli {

// The project version (CMakeLists.txt project(... VERSION)), e.g. "0.1.0".
const char* Version();
// The source revision: the commit's 12-digit short hash, with "-dirty" when tracked files
// had uncommitted changes; "unknown" when built outside a git checkout (or the
// ARCO_SOURCE_REVISION the build was configured with).
const char* SourceRevision();

// "arco 0.1.0 (git 1a2b3c4d5e6f)": what `arco --version` prints.
inline std::string VersionLine() {
  return std::string("arco ") + Version() + " (git " + SourceRevision() + ")";
}

}  // namespace arco::cli
