// Small order statistics shared by the layers.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace arco {

// Median of `v` (the mean of the two middle values when the size is even); NaN when
// empty. Takes a copy: nth_element reorders it.
inline double Median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  const size_t mid = v.size() / 2;
  const auto mid_it = v.begin() + static_cast<std::ptrdiff_t>(mid);
  std::nth_element(v.begin(), mid_it, v.end());
  const double upper = *mid_it;
  if (v.size() % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(v.begin(), mid_it));
}

}  // namespace arco
