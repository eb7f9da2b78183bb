// Folders written whole or not at all (the folder analogue of AtomicWriteFile).
#pragma once

#include <functional>
#include <string>

#include "arco/util/status.h"

namespace arco {

// `write` fills a fresh temporary sibling of `dir` (".<name>.tmp-<pid>"); on success
// the temporary folder replaces `dir` (any old `dir` is removed first), on failure it
// is removed and `dir` is left as it was. The parent of `dir` is created if needed.
Status AtomicWriteDirectory(const std::string& dir,
                            const std::function<Status(const std::string& tmp_dir)>& write);

}  // namespace arco
