// File helpers. Outputs are written whole or not at all: AtomicWriteFile writes a hidden
// temporary sibling and moves it into place only after a successful flush (one-file
// OutputSet, util/output_set.h: a folder or a missing parent folder is an error).
#pragma once

#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>

#include "arco/util/status.h"

namespace arco {

StatusOr<std::string> ReadFileToString(const std::string& path);

// A file's bytes, read-only, for as long as the object lives: a regular file is mapped
// into memory (mmap), so a 118 MB keypoints2d.npy is neither copied into a string nor
// zero-filled first (that was 4% of `arco run`'s CPU on the one-minute 20-camera take);
// anything else (a pipe, an empty file) is read into memory from the same descriptor. The
// messages for a missing file and a folder are ReadFileToString's. Moving keeps the view.
// arco replaces files by renaming a new one over them (AtomicWriteFile), which leaves a
// mapping's bytes as they were; a file truncated in place while mapped would fault.
class FileBytes {
 public:
  static StatusOr<FileBytes> Open(const std::string& path);
  std::string_view view() const { return view_; }

 private:
  struct Mapping;
  std::shared_ptr<const Mapping> mapping_;   // the mmap (unmapped by the last owner) ...
  std::shared_ptr<const std::string> copy_;  // ... or the bytes read
  std::string_view view_;
};

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

// A path stored in a manifest: a relative `path` (from the working folder) made relative
// to the folder `base` that holds the manifest, so the two can move together; an absolute
// one stays absolute (right from anywhere, as the user gave it). The inverse is
// ResolveCapturePath (mocap/capture.h): JoinPath(base, PathRelativeTo(path, base)) names
// `path`.
std::string PathRelativeTo(const std::string& path, const std::string& base);

// Natural order of file names: runs of digits compare as numbers, so frame2.png sorts
// before frame10.png (image folders, per-frame keypoint files).
bool NaturalLess(const std::string& a, const std::string& b);

}  // namespace arco
