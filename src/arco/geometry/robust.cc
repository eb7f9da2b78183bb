#include "arco/geometry/robust.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace arco {

int64_t RansacTrialsNeeded(double inlier_ratio, int sample_size, double confidence) {
  constexpr int64_t kMax = 1000000000;
  if (!(inlier_ratio > 0)) return kMax;
  if (inlier_ratio >= 1) return 1;
  const double good_sample = std::pow(inlier_ratio, sample_size);
  if (good_sample <= 0) return kMax;
  const double denom = std::log1p(-good_sample);
  if (!(denom < 0)) return kMax;
  const double n = std::ceil(std::log1p(-confidence) / denom);
  if (!(n < static_cast<double>(kMax))) return kMax;
  return std::max<int64_t>(1, static_cast<int64_t>(n));
}

std::vector<std::pair<int, int>> MakePairSchedule(int num_views, int max_pairs, uint64_t seed) {
  if (num_views < 0 || max_pairs < 1) {
    throw std::invalid_argument("MakePairSchedule: num_views must be >= 0 and max_pairs >= 1");
  }
  std::vector<std::pair<int, int>> pairs;
  const int64_t all = static_cast<int64_t>(num_views) * (num_views - 1) / 2;
  if (all <= max_pairs) {
    pairs.reserve(static_cast<size_t>(all));
    for (int i = 0; i < num_views; ++i) {
      for (int j = i + 1; j < num_views; ++j) pairs.emplace_back(i, j);
    }
    std::stable_sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) {
      return a.first + a.second < b.first + b.second;
    });
    return pairs;
  }
  pairs.reserve(static_cast<size_t>(max_pairs));
  std::vector<char> used(static_cast<size_t>(num_views) * num_views, 0);
  auto add = [&](int i, int j) {
    if (i > j) std::swap(i, j);
    char& flag = used[static_cast<size_t>(i) * num_views + j];
    if (i == j || flag) return false;
    flag = 1;
    pairs.emplace_back(i, j);
    return true;
  };
  int k = 2;
  while ((k + 1) * k / 2 <= max_pairs / 2 && k + 1 <= num_views) ++k;
  for (int s = 1; s < 2 * k - 2; ++s) {  // top-k pairs by ascending rank sum
    for (int i = 0; i < k; ++i) {
      const int j = s - i;
      if (j > i && j < k) add(i, j);
    }
  }
  SplitMix64 rng(seed ^ (static_cast<uint64_t>(num_views) << 32));
  // Random distinct pairs; the loop ends because max_pairs < all pairs.
  while (static_cast<int>(pairs.size()) < max_pairs) {
    add(rng.Uniform(num_views), rng.Uniform(num_views));
  }
  return pairs;
}

}  // namespace arco
