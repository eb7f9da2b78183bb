// Outputs written as one transaction: every output of a command is declared (and its
// location checked) before the work starts, written to a hidden temporary sibling, and
// moved into place together at the end. A failure at any point leaves every previous
// file and folder as it was and no temporary behind (docs/architecture.md, "Outputs").
#pragma once

#include <string>
#include <vector>

#include "arco/util/status.h"

namespace arco {

// When an existing folder may be replaced by a new one.
struct FolderReplace {
  bool overwrite = false;  // the command's --overwrite: replace a non-empty folder
  // A file an existing folder must hold to be replaced ("" = any folder), so that
  // `--overwrite` never deletes a folder that is not the command's own kind of output.
  std::string marker;
  std::string kind = "folder";  // "capture", "result folder": for messages
  std::string option = "--overwrite";
};

// "a/b/" and "a/b" name the same folder: trailing slashes (and "." parts) removed;
// "" stays "" and "/" stays "/".
std::string NormalizeOutputPath(const std::string& path);

// The checks of OutputSet::AddFile / AddFolder, for a command to make before its work
// starts; nothing is created. A folder's missing parents must be creatable (the nearest
// existing ancestor is a writable folder).
Status CheckOutputFile(const std::string& path);
Status CheckOutputFolder(const std::string& path, const FolderReplace& replace);

class OutputSet {
 public:
  OutputSet() = default;
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;
  ~OutputSet();  // removes the temporaries of an uncommitted set
  // While they exist, the temporaries are also removed by an interrupt (SIGINT, SIGTERM)
  // when the process installed util/interrupt.h's cleanup.

  // Declares the file `path` and returns the temporary path to write it to (created
  // empty now, which proves the folder writable). Errors, naming `path`: an existing
  // folder, a path ending in '/', a parent folder that does not exist or is not a
  // folder, an uncreatable temporary (the system's reason). An existing file is replaced.
  StatusOr<std::string> AddFile(const std::string& path);
  // Declares the folder `path` and returns an empty temporary folder to fill. Missing
  // parents are created. An existing folder that is empty is replaced; a non-empty one
  // only with `replace.overwrite` and, when `replace.marker` is set, when it holds it.
  StatusOr<std::string> AddFolder(const std::string& path, const FolderReplace& replace);
  // Declares that the file or folder `path` goes with this set: at Commit it is moved
  // aside like a replaced output and deleted once every output is in (put back if a move
  // fails), so a result never shows new outputs beside stale ones made from the old
  // (a re-run stage and the later stages it invalidates). Absent: nothing to do.
  Status AddRemoval(const std::string& path);

  // Moves every declared output into place, in order: an existing one is renamed aside
  // to a hidden sibling, the new one moved in, and the old ones deleted only once all are
  // in. If any move fails, the outputs already moved are taken back out and the old ones
  // restored. The temporaries are removed either way.
  Status Commit();

  // The final paths, as declared (normalized).
  std::vector<std::string> paths() const;

 private:
  struct Output {
    std::string path, tmp, old;
    bool folder = false;
    bool removal = false;  // AddRemoval: no temporary; the old one goes
  };
  std::vector<Output> outputs_;
  bool done_ = false;
};

// The hidden sibling of `path` used for its temporary (".<what>-<pid>.NAME").
std::string HiddenSibling(const std::string& path, const std::string& what);

// Removes what killed commands left in `path`'s parent folder: every ".tmp-PID.NAME" whose
// process PID no longer exists (any NAME: a temporary is never anyone's output), and a
// dead process's ".old-PID.NAME" when NAME itself exists (else the old one may be the only
// copy and is left alone). Temporaries of live processes are never touched. Returns how
// many entries went. OutputSet::AddFile / AddFolder call it, and the CLI for every output
// a command declares (cli/command.h), so a new start cleans up after an interrupted one.
int RemoveStaleTemporaries(const std::string& path);

}  // namespace arco
