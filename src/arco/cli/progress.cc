#include "arco/cli/progress.h"

#include <unistd.h>

#include <cstdio>

namespace arco::cli {

ProgressBar::ProgressBar(std::string label, int64_t total)
    : label_(std::move(label)), enabled_(::isatty(STDERR_FILENO) != 0) {
  if (total >= 0) SetTotal(total);
}

ProgressBar::~ProgressBar() { Finish(); }

void ProgressBar::StartStage(int index, int count, const std::string& name) {
  Finish();
  label_ = name;
  std::fprintf(stderr, "[%d/%d] %s\n", index, count, name.c_str());
}

void ProgressBar::SetTotal(int64_t total) {
  Finish();
  total_ = total;
  done_ = 0;
  last_draw_ = std::chrono::steady_clock::now();
  active_ = true;
}

void ProgressBar::Advance(int64_t done) {
  if (!active_) return;
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
  if (!active_.exchange(false)) return;
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  Draw(done_.load());
  std::fprintf(stderr, "\n");
}

}  // namespace arco::cli
