// The harmonic-peak fit on generated tones with known f0.
#include "arco/audio/harmonic_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "arco/audio/test_signals.h"

namespace arco::audio::testing {
namespace {

double Cents(double f, double truth) { return 1200.0 * std::log2(f / truth); }

std::vector<float> Tone(double f0, int harmonics, double rolloff, int rate, double seconds) {
  ToneOptions o;
  o.sample_rate_hz = rate;
  o.harmonics = harmonics;
  o.rolloff = rolloff;
  return RenderTone([f0](double) { return f0; }, seconds, o);
}

TEST(HarmonicPeakFit, FindsDetunedHarmonicToneWithinACent) {
  const int rate = 44100;
  // Keys from the double bass to the violin's top, each played 37 or 62 cents
  // off its nominal pitch (as FluidR3's worst samples are).
  for (double nominal : {41.2, 130.81, 440.0, 2349.3}) {
    for (double off : {37.0, -62.0}) {
      const double f0 = nominal * std::exp2(off / 1200.0);
      const int harmonics = nominal > 2000 ? 4 : 10;
      const auto x = Tone(f0, harmonics, 1.0, rate, 0.5);
      const int window = HarmonicFitWindow(rate, nominal);
      HarmonicPeakFit fit(rate, window);
      const double got = fit.F0Hz(x.data() + 1000, window, nominal);
      ASSERT_TRUE(std::isfinite(got)) << nominal << " " << off;
      EXPECT_NEAR(Cents(got, f0), 0.0, 1.0) << nominal << " " << off;
    }
  }
}

TEST(HarmonicPeakFit, WeakFundamentalAndSilence) {
  const int rate = 44100;
  const double f0 = 196.0 * std::exp2(20.0 / 1200.0);
  ToneOptions o;
  o.harmonics = 8;
  o.skip_fundamental = true;  // partials 2..8 still give the period
  const auto x = RenderTone([f0](double) { return f0; }, 0.3, o);
  const int window = HarmonicFitWindow(rate, 196.0);
  HarmonicPeakFit fit(rate, window);
  EXPECT_NEAR(Cents(fit.F0Hz(x.data(), window, 196.0), f0), 0.0, 1.0);
  const std::vector<float> silent(window, 0.0f);
  EXPECT_TRUE(std::isnan(fit.F0Hz(silent.data(), window, 196.0)));
}

}  // namespace
}  // namespace arco::audio::testing
