// The terminal's progress (arco::Progress, util/progress.h): "[i/n] stage" lines and a
// progress bar on stderr. The bar is only drawn when stderr is a terminal (so logs and CI
// output stay clean); Advance() is thread-safe.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

#include "arco/util/progress.h"

namespace arco::cli {

class ProgressBar : public Progress {
 public:
  // With total >= 0 a bar labelled `label` starts at once; otherwise at SetTotal().
  explicit ProgressBar(std::string label = "", int64_t total = -1);
  ~ProgressBar() override;

  // Ends the current bar and prints "[index/count] name"; later bars are labelled name.
  void StartStage(int index, int count, const std::string& name) override;
  // Ends the current bar and starts a new one of `total` units.
  void SetTotal(int64_t total) override;
  void Advance(int64_t done) override;
  void Add(int64_t done = 1) { Advance(done); }
  // Ends the current bar (its last state and a newline).
  void Finish();

 private:
  void Draw(int64_t done);
  std::string label_;
  int64_t total_ = 0;
  std::atomic<int64_t> done_{0};
  std::atomic<bool> active_{false};
  const bool enabled_;
  std::mutex mutex_;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace arco::cli
