// Deterministic parallel loops: work item i always computes the same result and
// writes only its own output slot, so results do not depend on thread count or
// scheduling. Items are handed out in contiguous chunks from an atomic counter.
// An exception thrown by a work item reaches the caller (see ParallelFor).
#pragma once

#include <algorithm>
#include <atomic>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace arco {

// Number of worker threads for `requested` (0 = hardware concurrency).
inline int ResolveThreadCount(int requested) {
  if (requested > 0) return requested;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw == 0 ? 1 : static_cast<int>(hw);
}

// Calls fn(i) for i in [0, n) on up to `num_threads` threads (0 = all cores).
// fn(i, thread_index) may use per-thread scratch indexed by thread_index.
//
// Exceptions: when fn throws, no worker takes a new item after that, every worker
// finishes the item it is running, all threads are joined, and the exception is
// rethrown on the calling thread. When several items throw, the one with the lowest
// item index among those that ran is rethrown (with one thread, or n = 1, that is the
// first failing item, as in a plain loop; with more threads, which later items still
// ran before the others stopped depends on scheduling).
inline void ParallelFor(int64_t n, int num_threads,
                        const std::function<void(int64_t i, int thread_index)>& fn,
                        int64_t chunk = 16) {
  const int threads = static_cast<int>(std::min<int64_t>(ResolveThreadCount(num_threads),
                                                         std::max<int64_t>(1, n)));
  if (threads <= 1) {
    for (int64_t i = 0; i < n; ++i) fn(i, 0);
    return;
  }
  std::atomic<int64_t> next{0};
  std::atomic<bool> stop{false};
  std::mutex error_mutex;
  std::exception_ptr error;
  int64_t error_item = n;
  auto worker = [&](int t) {
    for (;;) {
      if (stop.load(std::memory_order_relaxed)) return;
      const int64_t start = next.fetch_add(chunk);
      if (start >= n) return;
      const int64_t end = std::min(n, start + chunk);
      for (int64_t i = start; i < end; ++i) {
        if (stop.load(std::memory_order_relaxed)) return;
        try {
          fn(i, t);
        } catch (...) {
          std::lock_guard<std::mutex> lock(error_mutex);
          if (i < error_item) {
            error_item = i;
            error = std::current_exception();
          }
          stop.store(true, std::memory_order_relaxed);
          return;
        }
      }
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(static_cast<size_t>(threads - 1));
  try {
    for (int t = 1; t < threads; ++t) pool.emplace_back(worker, t);
  } catch (...) {  // no thread could be started: stop the started ones, then report
    stop.store(true);
    for (auto& th : pool) th.join();
    throw;
  }
  worker(0);
  for (auto& th : pool) th.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace arco
