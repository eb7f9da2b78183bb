// File helpers. Outputs are written whole or not at all: AtomicWriteFile writes a hidden
// temporary sibling and moves it into place only after a successful flush (one-file
// OutputSet, util/output_set.h: a folder or a missing parent folder is an error).
#pragma once

#include <functional>
#include <ostream>
#include <string>

#include "arco/util/status.h"

namespace arco {

StatusOr<std::string> ReadFileToString(const std::string& path);

// Writes `contents` to `path` atomically (temporary file + rename).
Status AtomicWriteFile(const std::string& path, const std::string& contents);

// Calls `writer` with a stream to a temporary file; renames into place only when
// the writer returns OK and the stream is good. On failure nothing is left behind.
Status AtomicWriteWith(const std::string& path,
                       const std::function<Status(std::ostream&)>& writer);

// Creates a directory and its parents; OK if it already exists.
Status MakeDirectories(const std::string& path);

bool FileExists(const std::string& path);

// "a/b" + "c.json" -> "a/b/c.json" (std::filesystem based).
std::string JoinPath(const std::string& a, const std::string& b);

}  // namespace arco
