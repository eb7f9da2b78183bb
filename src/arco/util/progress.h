// The one progress interface of long work: the pipeline's stages report through it, the
// CLI's progress bar implements it, and bindings or a workflow engine can implement it too.
// Library code never prints; it only calls these hooks.
#pragma once

#include <cstdint>
#include <string>

namespace arco {

class Progress {
 public:
  virtual ~Progress() = default;
  // Stage `index` of `count` (from 1) begins.
  virtual void StartStage(int /*index*/, int /*count*/, const std::string& /*name*/) {}
  // The current stage's amount of work is known, in its own units (frames, chunks, ...).
  virtual void SetTotal(int64_t /*total*/) {}
  // `done` more units of the current stage are finished. Called from worker threads:
  // implementations must be thread-safe.
  virtual void Advance(int64_t /*done*/) {}
};

// Does nothing: the default where a caller passes no progress.
inline Progress& NoProgress() {
  static Progress none;
  return none;
}

}  // namespace arco
