// A terminal progress bar on stderr, only drawn when stderr is a terminal
// (so logs and CI output stay clean); thread-safe Update().
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace arco::cli {

class ProgressBar {
 public:
  ProgressBar(std::string label, int64_t total);
  ~ProgressBar();
  void Add(int64_t done = 1);
  void Finish();

 private:
  void Draw(int64_t done);
  std::string label_;
  int64_t total_;
  std::atomic<int64_t> done_{0};
  bool enabled_;
  bool finished_ = false;
  std::mutex mutex_;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace arco::cli
