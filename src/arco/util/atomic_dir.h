// Folders written whole or not at all (the folder analogue of AtomicWriteFile), through
// the one output mechanism of util/output_set.h.
#pragma once

#include <functional>
#include <string>

#include "arco/util/output_set.h"
#include "arco/util/status.h"

namespace arco {

// `write` fills a fresh hidden temporary sibling of `dir`; on success it replaces `dir`
// (OutputSet::Commit: the old folder is moved aside, the new one in, then the old one
// deleted; if the move fails the old one is put back), on failure it is removed and `dir`
// is left as it was. "dir/" and "dir" are the same folder; missing parents are created.
// An existing non-empty `dir` is replaced only as `replace` allows (util/output_set.h).
Status AtomicWriteDirectory(const std::string& dir,
                            const FolderReplace& replace,
                            const std::function<Status(const std::string& tmp_dir)>& write);

// For a folder that is always the caller's own (a stage folder inside a result folder):
// any existing folder is replaced.
Status AtomicWriteDirectory(const std::string& dir,
                            const std::function<Status(const std::string& tmp_dir)>& write);

}  // namespace arco
