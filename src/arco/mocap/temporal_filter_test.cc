#include "arco/mocap/temporal_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

namespace arco {
namespace {

constexpr double kFps = 30.0;

std::vector<double> Sine(int n, double freq_hz, double amplitude = 1.0) {
  std::vector<double> x(n);
  for (int i = 0; i < n; ++i) x[i] = amplitude * std::sin(2 * M_PI * freq_hz * i / kFps);
  return x;
}

double MaxAbsInRange(const std::vector<double>& x, int from, int to) {
  double m = 0;
  for (int i = from; i < to; ++i) m = std::max(m, std::abs(x[i]));
  return m;
}

double Rms(const std::vector<double>& x, int from, int to) {
  double s = 0;
  for (int i = from; i < to; ++i) s += x[i] * x[i];
  return std::sqrt(s / (to - from));
}

TemporalFilterOptions Spec(const std::string& s) {
  auto o = ParseFilterSpec(s);
  EXPECT_TRUE(o.ok()) << o.status().message();
  return *o;
}

TEST(Butterworth, ZeroPhasePassbandAndHalfPowerAtCutoff) {
  const auto o = Spec("butterworth:6:4");
  // 1 Hz passes unchanged and without delay.
  auto slow = Sine(300, 1.0);
  const auto original = slow;
  FilterTrajectory(o, kFps, &slow);
  for (int i = 30; i < 270; ++i) EXPECT_NEAR(slow[i], original[i], 2e-3) << i;
  // filtfilt squares the magnitude response: 0.5 at the cutoff.
  // (Compared by RMS: at 5 samples per period the sampled peaks are not the amplitude.)
  auto at_cutoff = Sine(600, 6.0);
  const auto unfiltered = at_cutoff;
  FilterTrajectory(o, kFps, &at_cutoff);
  EXPECT_NEAR(Rms(at_cutoff, 200, 400) / Rms(unfiltered, 200, 400), 0.5, 0.01);
  // 12 Hz: |H|^2 = 1 / (1 + (tan(pi 12/30) / tan(pi 6/30))^8)... far below 1%.
  auto fast = Sine(600, 12.0);
  FilterTrajectory(o, kFps, &fast);
  EXPECT_LT(MaxAbsInRange(fast, 200, 400), 0.01);
}

TEST(Butterworth, ConstantsAndRampsSurviveTheEdges) {
  const auto o = Spec("butterworth:4:2");
  std::vector<double> c(50, 3.25);
  FilterTrajectory(o, kFps, &c);
  for (double v : c) EXPECT_NEAR(v, 3.25, 1e-12);
  std::vector<double> ramp(200);
  for (int i = 0; i < 200; ++i) ramp[i] = 0.1 * i - 2;
  auto r = ramp;
  FilterTrajectory(o, kFps, &r);
  // Zero phase keeps a line exactly away from the ends; the start-up transient of
  // the padded ends stays small.
  for (int i = 0; i < 200; ++i) {
    EXPECT_NEAR(r[i], ramp[i], (i < 40 || i >= 160) ? 1e-3 : 1e-9) << i;
  }
}

TEST(SavitzkyGolay, KeepsPolynomialsUpToItsOrderIncludingEdges) {
  const auto o = Spec("savgol:9:3");
  std::vector<double> x(40);
  for (int i = 0; i < 40; ++i) x[i] = 0.5 - 0.3 * i + 0.02 * i * i - 0.001 * i * i * i;
  auto y = x;
  FilterTrajectory(o, kFps, &y);
  for (int i = 0; i < 40; ++i) EXPECT_NEAR(y[i], x[i], 1e-9) << i;
}

TEST(SavitzkyGolay, ReducesNoiseByTheCentreWeight) {
  // White noise variance shrinks by sum of squared weights = the centre weight of the
  // smoothing (projection) matrix: for window 9, order 2 it is 59/231.
  std::mt19937 rng(1);
  std::normal_distribution<double> n(0, 1);
  std::vector<double> x(20000);
  for (double& v : x) v = n(rng);
  FilterTrajectory(Spec("savgol:9:2"), kFps, &x);
  double var = 0;
  for (int i = 10; i < 19990; ++i) var += x[i] * x[i];
  var /= 19980;
  EXPECT_NEAR(var, 59.0 / 231.0, 0.015);
}

TEST(SavitzkyGolay, ShortSegmentsUseASmallerWindow) {
  std::vector<double> x = {1, 2, 3, 4, 5};  // a line: any window keeps it
  FilterTrajectory(Spec("savgol:11:2"), kFps, &x);
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(x[i], i + 1, 1e-12);
}

TEST(OneEuro, WithoutBetaIsAFirstOrderLowPass) {
  const auto o = Spec("oneeuro:2:0");
  std::vector<double> x(20, 1.0);
  x[0] = 0;
  FilterTrajectory(o, kFps, &x);
  const double alpha = 1.0 / (1.0 + kFps / (2 * M_PI * 2.0));
  for (int i = 1; i < 20; ++i) EXPECT_NEAR(x[i], 1 - std::pow(1 - alpha, i), 1e-12) << i;
}

TEST(OneEuro, BetaReducesLagOnFastMotion) {
  std::vector<double> ramp(60);
  for (int i = 0; i < 60; ++i) ramp[i] = 0.05 * i;  // 1.5 units/s
  auto slow = ramp, adaptive = ramp;
  FilterTrajectory(Spec("oneeuro:1:0"), kFps, &slow);
  FilterTrajectory(Spec("oneeuro:1:5"), kFps, &adaptive);
  EXPECT_LT(std::abs(adaptive[59] - ramp[59]), 0.3 * std::abs(slow[59] - ramp[59]));
}

TEST(FilterTrajectory, FillsShortGapsAndKeepsLongOnes) {
  const double nan = NAN;
  std::vector<double> x = {0, 1, nan, nan, 4, 5, nan, nan, nan, nan, 10, 11};
  TemporalFilterOptions none;
  none.max_gap_frames = 3;
  FilterTrajectory(none, kFps, &x);
  EXPECT_DOUBLE_EQ(x[2], 2);
  EXPECT_DOUBLE_EQ(x[3], 3);
  for (int i = 6; i < 10; ++i) EXPECT_TRUE(std::isnan(x[i])) << i;
  std::vector<double> edge = {nan, 1, 2, nan};
  FilterTrajectory(none, kFps, &edge);  // ends are not extrapolated
  EXPECT_TRUE(std::isnan(edge[0]) && std::isnan(edge[3]));
}

TEST(FilterTrajectory, SegmentsAcrossLongGapsDoNotLeak) {
  std::vector<double> x(80, NAN);
  for (int i = 0; i < 30; ++i) x[i] = 1.0;
  for (int i = 50; i < 80; ++i) x[i] = -7.0;
  for (const char* spec : {"butterworth:3:4", "savgol:7:2", "oneeuro:1:0.5"}) {
    auto y = x;
    FilterTrajectory(Spec(spec), kFps, &y);
    for (int i = 0; i < 30; ++i) EXPECT_NEAR(y[i], 1.0, 1e-9) << spec << " " << i;
    for (int i = 30; i < 50; ++i) EXPECT_TRUE(std::isnan(y[i])) << spec;
    for (int i = 50; i < 80; ++i) EXPECT_NEAR(y[i], -7.0, 1e-9) << spec << " " << i;
  }
}

TEST(FilterPoints, FiltersOnlyTheChosenPoints) {
  NpyArray<double> pts;
  pts.shape = {40, 2, 3};
  pts.data.resize(240);
  std::mt19937 rng(2);
  std::normal_distribution<double> n(0, 1);
  for (double& v : pts.data) v = n(rng);
  const auto before = pts;
  FilterPoints(Spec("savgol:5:1"), kFps, {1}, &pts);
  for (int f = 0; f < 40; ++f) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(pts.at(f, 0, k), before.at(f, 0, k));
  }
  EXPECT_NE(pts.at(20, 1, 0), before.at(20, 1, 0));
  EXPECT_THROW(FilterPoints(Spec("none"), kFps, {2}, &pts), std::invalid_argument);
}

TEST(ParseFilterSpec, ParsesAndRejects) {
  auto b = Spec("butterworth:8:2");
  EXPECT_EQ(b.kind, FilterKind::kButterworth);
  EXPECT_EQ(b.cutoff_hz, 8);
  EXPECT_EQ(b.order, 2);
  EXPECT_EQ(FilterSpecToString(b), "butterworth:8:2");
  EXPECT_EQ(Spec("savgol").window, 9);
  EXPECT_EQ(Spec("oneeuro:1.5:0.1:2").d_cutoff_hz, 2);
  EXPECT_EQ(Spec("none").kind, FilterKind::kNone);
  EXPECT_FALSE(ParseFilterSpec("kalman").ok());
  EXPECT_FALSE(ParseFilterSpec("butterworth:x").ok());
  EXPECT_FALSE(ParseFilterSpec("savgol:9.5").ok());
  EXPECT_FALSE(ParseFilterSpec("savgol:9:2:1").ok());
  EXPECT_FALSE(ParseFilterSpec("").ok());
}

TEST(TemporalFilterOptions, ValidateRejectsBadValues) {
  EXPECT_FALSE(Spec("butterworth:15").Validate(30).ok());  // at Nyquist
  EXPECT_FALSE(Spec("butterworth:6:9").Validate(30).ok());
  EXPECT_FALSE(Spec("savgol:8:2").Validate(30).ok());  // even window
  EXPECT_FALSE(Spec("savgol:5:5").Validate(30).ok());
  EXPECT_FALSE(Spec("oneeuro:0").Validate(30).ok());
  EXPECT_FALSE(Spec("oneeuro:1:-1").Validate(30).ok());
  EXPECT_FALSE(Spec("none").Validate(0).ok());
  TemporalFilterOptions o;
  o.max_gap_frames = -1;
  EXPECT_FALSE(o.Validate(30).ok());
  std::vector<double> x(10, 0);
  EXPECT_THROW(FilterTrajectory(Spec("savgol:4:2"), kFps, &x), std::invalid_argument);
}

}  // namespace
}  // namespace arco
