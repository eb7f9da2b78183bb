#include "arco/util/stats.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace arco {
namespace {

TEST(Median, OddEvenAndEmpty) {
  EXPECT_EQ(Median({3, 1, 2}), 2);
  EXPECT_EQ(Median({4, 1, 3, 2}), 2.5);  // mean of the middle two
  EXPECT_TRUE(std::isnan(Median({})));
}

TEST(Median, MatchesSortedDefinitionBitForBit) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1e3, 1e3);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<double> v(1 + trial % 17);
    for (double& x : v) x = u(rng);
    std::vector<double> sorted = v;
    std::sort(sorted.begin(), sorted.end());
    const size_t n = sorted.size();
    const double expected = n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2] + sorted[n / 2 - 1]);
    EXPECT_EQ(Median(v), expected);
    EXPECT_EQ(UpperMedian(v), sorted[n / 2]);
  }
}

// Why two medians: the upper median is always one of the samples (a transcription's
// from_nut_mm is a measured position, a hand fit's residual a measured residual), the
// averaged one is not; on an even count they differ, and with them every output that
// depends on them. Each call site keeps the one it always used.
TEST(UpperMedian, IsASampleWhereTheAveragedMedianIsNot) {
  const std::vector<double> v = {10.0, 20.0, 30.0, 40.0};
  EXPECT_EQ(UpperMedian(v), 30.0);
  EXPECT_EQ(Median(v), 25.0);
  EXPECT_EQ(UpperMedian({5.0}), Median({5.0}));
  EXPECT_EQ(UpperMedian({3.0, 1.0, 2.0}), Median({3.0, 1.0, 2.0}));  // odd: the same
  EXPECT_TRUE(std::isnan(UpperMedian({})));
}

// A float range is averaged in double (as the triangulation summary always did): the
// float mean of the middle pair would round differently.
TEST(MedianInPlace, FloatRangeAveragesInDouble) {
  std::vector<float> v = {1.0f, 1.0f + 1.1920929e-7f, 7.0f, -3.0f};
  const double expected = 0.5 * (static_cast<double>(v[0]) + static_cast<double>(v[1]));
  EXPECT_EQ(MedianInPlace(v.begin(), v.end()), expected);
  const float in_float = 0.5f * (v[0] + v[1]);
  EXPECT_NE(static_cast<double>(in_float), expected);
}

TEST(MedianAbsDeviation, RobustScaleOfNormalData) {
  EXPECT_EQ(MedianAbsDeviation({1, 2, 3, 4, 100}, 3), 1);
  EXPECT_TRUE(std::isnan(MedianAbsDeviation({}, 0)));
  std::mt19937 rng(3);
  std::normal_distribution<double> g(5.0, 2.0);
  std::vector<double> v(20001);
  for (double& x : v) x = g(rng);
  v[0] = 1e9;  // one wild outlier moves neither
  const double sigma = kMadToSigma * MedianAbsDeviation(v, Median(v));
  EXPECT_NEAR(sigma, 2.0, 0.05);
}

TEST(InterpolatedQuantile, InterpolatesBetweenOrderStatistics) {
  const std::vector<double> v = {4, 1, 3, 2};
  EXPECT_EQ(InterpolatedQuantile(v, 0.0), 1);
  EXPECT_EQ(InterpolatedQuantile(v, 1.0), 4);
  EXPECT_DOUBLE_EQ(InterpolatedQuantile(v, 0.5), 2.5);
  EXPECT_DOUBLE_EQ(InterpolatedQuantile(v, 0.9), 3.7);
  EXPECT_DOUBLE_EQ(InterpolatedQuantile(v, 0.1), 1.3);
  EXPECT_EQ(InterpolatedQuantile({7}, 0.3), 7);
}

TEST(FitLine, RecoversALineAndRefusesTooFewOrNoSpread) {
  double intercept = 7, slope = 7;
  EXPECT_TRUE(FitLine({{0, 1}, {1, 3}, {2, 5}, {3, 7}}, &intercept, &slope));
  EXPECT_DOUBLE_EQ(slope, 2.0);
  EXPECT_DOUBLE_EQ(intercept, 1.0);
  // Noisy points: the least-squares fit (numpy.polyfit gives 1.3 and 0.3 for these).
  EXPECT_TRUE(FitLine({{0, 0}, {1, 2}, {2, 3}, {3, 4}}, &intercept, &slope));
  EXPECT_NEAR(slope, 1.3, 1e-12);
  EXPECT_NEAR(intercept, 0.3, 1e-12);
  intercept = slope = 7;
  EXPECT_FALSE(FitLine({{1, 2}}, &intercept, &slope));
  EXPECT_FALSE(FitLine({{1, 2}, {1, 5}}, &intercept, &slope));
  EXPECT_EQ(slope, 7);  // untouched
  EXPECT_EQ(intercept, 7);
}

}  // namespace
}  // namespace arco
