// Small statistics shared by the layers: one median, its variants, the robust scale (MAD),
// quantiles and a least-squares line. Outputs depend bit for bit on which median a call site uses,
// so the variants are named and each says where it differs (stats_test.cc shows the cases).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <iterator>
#include <utility>
#include <vector>

namespace arco {

// Median of [first, last) (the mean of the two middle values when the count is even);
// NaN when empty. Reorders the range (nth_element); works on float or double ranges and
// averages in double.
template <typename RandomIt>
double MedianInPlace(RandomIt first, RandomIt last) {
  const auto n = std::distance(first, last);
  if (n == 0) return std::nan("");
  const RandomIt mid = first + n / 2;
  std::nth_element(first, mid, last);
  const double upper = static_cast<double>(*mid);
  if (n % 2 == 1) return upper;
  return 0.5 * (upper + static_cast<double>(*std::max_element(first, mid)));
}

// Median of `v` (the mean of the two middle values when the size is even); NaN when
// empty. Takes a copy: nth_element reorders it.
inline double Median(std::vector<double> v) { return MedianInPlace(v.begin(), v.end()); }

// Upper median of [first, last): the value at index n / 2 of the sorted values, i.e. for
// an even count the larger of the two middle values, never their mean. Always one of the
// samples (a representative element, e.g. a measured position). NaN when empty.
// Reorders the range.
template <typename RandomIt>
double UpperMedianInPlace(RandomIt first, RandomIt last) {
  const auto n = std::distance(first, last);
  if (n == 0) return std::nan("");
  const RandomIt mid = first + n / 2;
  std::nth_element(first, mid, last);
  return static_cast<double>(*mid);
}

// UpperMedianInPlace on a copy of `v`.
inline double UpperMedian(std::vector<double> v) { return UpperMedianInPlace(v.begin(), v.end()); }

// MAD to standard deviation for normally distributed data: sigma ~ kMadToSigma * MAD.
constexpr double kMadToSigma = 1.4826;

// Median absolute deviation from `center` (usually Median(v)): Median(|v_i - center|);
// NaN when empty. Multiply by kMadToSigma for a robust standard deviation.
inline double MedianAbsDeviation(const std::vector<double>& v, double center) {
  std::vector<double> deviation(v.size());
  for (size_t i = 0; i < v.size(); ++i) deviation[i] = std::abs(v[i] - center);
  return MedianInPlace(deviation.begin(), deviation.end());
}

// Quantile q in [0, 1] of `v` with linear interpolation between the order statistics
// around q * (n - 1) (R's type 7, numpy's default); q = 0.5 is the median up to
// rounding (Median averages the middle pair as 0.5 * (a + b)). `v` must not be
// empty.
inline double InterpolatedQuantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos));
  const size_t hi = std::min(v.size() - 1, lo + 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

// Least-squares line y = intercept + slope x through the (x, y) samples (means first,
// then the centred sums). False, leaving both untouched, with fewer than two samples or
// no spread in x.
inline bool FitLine(const std::vector<std::pair<double, double>>& xy,
                    double* intercept,
                    double* slope) {
  if (xy.size() < 2) return false;
  double sx = 0, sy = 0;
  for (const auto& [x, y] : xy) sx += x, sy += y;
  const double n = static_cast<double>(xy.size());
  const double mx = sx / n, my = sy / n;
  double sxx = 0, sxy = 0;
  for (const auto& [x, y] : xy) sxx += (x - mx) * (x - mx), sxy += (x - mx) * (y - my);
  if (!(sxx > 0)) return false;
  *slope = sxy / sxx;
  *intercept = my - *slope * mx;
  return true;
}

}  // namespace arco
