// Deterministic parallel loops: work item i always computes the same result and
// writes only its own output slot, so results do not depend on thread count or
// scheduling. Items are handed out in contiguous chunks from an atomic counter.
#pragma once

#include <algorithm>
#include <atomic>
#include <functional>
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
  auto worker = [&](int t) {
    for (;;) {
      const int64_t start = next.fetch_add(chunk);
      if (start >= n) break;
      const int64_t end = std::min(n, start + chunk);
      for (int64_t i = start; i < end; ++i) fn(i, t);
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(static_cast<size_t>(threads - 1));
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker, t);
  worker(0);
  for (auto& th : pool) th.join();
}

}  // namespace arco
