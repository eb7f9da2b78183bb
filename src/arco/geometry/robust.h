// Building blocks for deterministic RANSAC (Fischler & Bolles 1981) over views:
// a small seeded generator with a portable output sequence, the classic trial-count
// bound, and a pair schedule that tries the most promising view pairs first without
// enumerating all n(n-1)/2 pairs when there are many views.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

namespace arco {

// SplitMix64 (Steele, Lea & Flood 2014): the same sequence on every platform, unlike
// std::uniform_int_distribution, so sampled results are bit-for-bit reproducible.
class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}
  uint64_t Next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  // Uniform integer in [0, n) (n > 0); the modulo bias is < n / 2^64.
  int Uniform(int n) { return static_cast<int>(Next() % static_cast<uint64_t>(n)); }

 private:
  uint64_t state_;
};

// Trials needed so that, with probability `confidence`, at least one sample of
// `sample_size` elements is outlier-free when a fraction `inlier_ratio` are inliers:
// N = log(1 - confidence) / log(1 - inlier_ratio^sample_size). Returns 1 when the
// ratio is 1 and a large number (capped at 1e9) when it is 0.
int64_t RansacTrialsNeeded(double inlier_ratio, int sample_size, double confidence);

// The order in which RANSAC tries view pairs, for `num_views` views sorted by
// decreasing detection confidence (index 0 = most confident). When all pairs fit in
// `max_pairs`, returns every pair, most confident first (ascending rank sum).
// Otherwise returns `max_pairs` distinct pairs: all pairs among the top-k views (k
// the largest with k(k-1)/2 <= max_pairs / 2), then pairs drawn with a SplitMix64
// generator seeded by `seed`, so every view can take part. Deterministic.
std::vector<std::pair<int, int>> MakePairSchedule(int num_views, int max_pairs, uint64_t seed);

}  // namespace arco
