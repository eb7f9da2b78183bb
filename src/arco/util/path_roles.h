// An output is never an input (docs/architecture.md, "Outputs"): a command declares the
// files and folders it reads and the ones it writes, each with the flag (or argument) that
// named it, and checks them together before any work. Paths are compared as the system
// resolves them (absolute, through symbolic links and `..`, then the same file by device
// and inode), so `m.wav`, `./m.wav`, `link-to-m.wav` and `d/../m.wav` are one file.
#pragma once

#include <string>
#include <vector>

#include "arco/util/status.h"

namespace arco {

class PathRoles {
 public:
  // A file or folder the command reads. `label` names it for the user: the flag
  // ("--calibration"), the argument ("INPUT"), or where it came from ("the capture's audio
  // (cap/capture.json)"). Empty paths are ignored; a missing path is still compared.
  void AddInput(const std::string& label, const std::string& path);
  // An input folder the command also writes into, by design (`arco detect CAPTURE` writes
  // CAPTURE/keypoints2d.npy): outputs may lie inside it, but may not be it or contain it.
  void AddOwnedFolder(const std::string& label, const std::string& path);
  // A file or folder the command writes (or replaces).
  void AddOutput(const std::string& label, const std::string& path);

  // Ok, or one error for the first output that
  // - is an input:                "m.wav: -o is the input INPUT; an output never replaces
  //                                an input (choose another path)"
  // - lies inside an input folder: "res/result.json: -o is inside the input folder
  //                                RESULT_DIR (res); ..."
  // - contains an input (a folder that would be replaced with the input inside it), or
  // - is another output.
  Status Check() const;

  const std::vector<std::string>& output_paths() const { return output_paths_; }

 private:
  struct Entry {
    std::string label, path;
    bool owned = false;
  };
  std::vector<Entry> inputs_, outputs_;
  std::vector<std::string> output_paths_;
};

// The path as the system resolves it: absolute, trailing slashes and `.`/`..` removed,
// symbolic links followed as far as the path exists.
std::string ResolvePath(const std::string& path);

// Whether resolved path `inner` lies strictly inside resolved folder `outer`.
bool PathIsInside(const std::string& inner, const std::string& outer);

}  // namespace arco
