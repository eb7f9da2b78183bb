#include "arco/cli/progress.h"

#include <unistd.h>

#include <cstdio>

namespace arco::cli {

ProgressBar::ProgressBar(std::string label, int64_t total)
    : label_(std::move(label)),
      total_(total),
      enabled_(::isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

ProgressBar::~ProgressBar() { Finish(); }

void ProgressBar::Add(int64_t done) {
  const int64_t now_done = done_.fetch_add(done) + done;
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard<std::mutex> lock(mutex_);
  if (now - last_draw_ < std::chrono::milliseconds(100) && now_done < total_) return;
  last_draw_ = now;
  Draw(now_done);
}

void ProgressBar::Draw(int64_t done) {
  const int width = 30;
  const double frac = total_ > 0 ? static_cast<double>(done) / total_ : 1.0;
  const int filled = static_cast<int>(frac * width);
  std::fprintf(stderr, "\r%-14s [%s%s] %3d%% (%lld/%lld)", label_.c_str(),
               std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(),
               static_cast<int>(frac * 100), static_cast<long long>(done),
               static_cast<long long>(total_));
  std::fflush(stderr);
}

void ProgressBar::Finish() {
  if (finished_) return;
  finished_ = true;
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  Draw(done_.load());
  std::fprintf(stderr, "\n");
}

}  // namespace arco::cli
