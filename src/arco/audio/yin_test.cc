// pYIN candidates on synthetic tones with known f0.
#include "arco/audio/yin.h"

#include <gtest/gtest.h>

#include <cmath>

#include "arco/audio/test_signals.h"

namespace arco::audio {
namespace {

double Cents(double f, double truth) { return 1200.0 * std::log2(f / truth); }

struct Case {
  double f0_hz;
  int rate;
  double min_hz, max_hz;
};

// Best candidate of a frame centred in a steady tone.
FrameCandidates AnalyzeTone(const Case& c, const testing::ToneOptions& tone) {
  YinOptions o;
  o.sample_rate_hz = c.rate;
  o.min_f0_hz = c.min_hz;
  o.max_f0_hz = c.max_hz;
  YinAnalyzer yin(o);
  testing::ToneOptions t = tone;
  t.sample_rate_hz = c.rate;
  const auto x = testing::RenderTone([&](double) { return c.f0_hz; }, 0.5, t);
  FrameCandidates out;
  yin.Analyze(x.data() + x.size() / 2 - yin.window_length() / 2, &out);
  return out;
}

const Case kCases[] = {
    {41.2, 16000, 38, 1200},   // bass E1
    {65.41, 16000, 60, 2000},  // cello C2
    {220.0, 16000, 60, 2000},
    {987.77, 16000, 60, 2000},   // cello B5
    {130.81, 24000, 120, 2800},  // viola C3
    {196.0, 32000, 180, 4200},   // violin G3
    {1318.5, 32000, 180, 4200},
    {3520.0, 32000, 180, 4200},  // violin A7 (issue: >= 3.5 kHz)
};

TEST(YinAnalyzer, PureTonesSubCent) {
  for (const Case& c : kCases) {
    testing::ToneOptions t;
    const auto out = AnalyzeTone(c, t);
    ASSERT_GT(out.count, 0) << c.f0_hz;
    EXPECT_NEAR(Cents(out.candidates[0].f0_hz, c.f0_hz), 0.0, 0.5) << c.f0_hz;
    EXPECT_GT(out.candidates[0].probability, 0.9) << c.f0_hz;
  }
}

TEST(YinAnalyzer, HarmonicRichTonesSubCent) {
  for (const Case& c : kCases) {
    testing::ToneOptions t;
    t.harmonics = 30;
    t.rolloff = 1.0;
    const auto out = AnalyzeTone(c, t);
    ASSERT_GT(out.count, 0) << c.f0_hz;
    EXPECT_NEAR(Cents(out.candidates[0].f0_hz, c.f0_hz), 0.0, 0.5) << c.f0_hz;
  }
}

TEST(YinAnalyzer, MissingFundamentalGivesTheFundamental) {
  for (const Case& c : kCases) {
    if (c.f0_hz * 3 > c.rate / 2.0) continue;
    testing::ToneOptions t;
    t.harmonics = 12;
    t.rolloff = 0.5;
    t.skip_fundamental = true;
    const auto out = AnalyzeTone(c, t);
    ASSERT_GT(out.count, 0) << c.f0_hz;
    EXPECT_NEAR(Cents(out.candidates[0].f0_hz, c.f0_hz), 0.0, 1.0) << c.f0_hz;
  }
}

TEST(YinAnalyzer, DcOffsetAndClippingDoNotMoveThePitch) {
  for (const Case& c : {kCases[1], kCases[3], kCases[6]}) {
    testing::ToneOptions dc;
    dc.harmonics = 8;
    dc.dc = 0.4;
    const auto a = AnalyzeTone(c, dc);
    ASSERT_GT(a.count, 0);
    EXPECT_NEAR(Cents(a.candidates[0].f0_hz, c.f0_hz), 0.0, 0.5);
    testing::ToneOptions clipped;
    clipped.harmonics = 4;
    clipped.amplitude = 1.0;
    clipped.clip = 0.3;  // heavy clipping
    const auto b = AnalyzeTone(c, clipped);
    ASSERT_GT(b.count, 0);
    // Clipping at the analysis rate aliases partials above Nyquist back as
    // inharmonic components; only low notes (aliases far down) stay sub-cent.
    const double tolerance = 20 * c.f0_hz < c.rate / 2.0 ? 1.0 : 5.0;
    EXPECT_NEAR(Cents(b.candidates[0].f0_hz, c.f0_hz), 0.0, tolerance) << c.f0_hz;
  }
}

TEST(YinAnalyzer, NoisyToneStillFoundAt20Db) {
  testing::ToneOptions t;
  t.harmonics = 10;
  t.amplitude = 0.3;
  t.noise = 0.3 * 0.1;  // about 20 dB SNR
  const auto out = AnalyzeTone(kCases[2], t);
  ASSERT_GT(out.count, 0);
  EXPECT_NEAR(Cents(out.candidates[0].f0_hz, 220.0), 0.0, 5.0);
}

TEST(YinAnalyzer, SilenceAndWhiteNoiseHaveNoConfidentPitch) {
  testing::ToneOptions silent;
  silent.amplitude = 0;
  EXPECT_EQ(AnalyzeTone(kCases[2], silent).count, 0);
  testing::ToneOptions noise;
  noise.amplitude = 0;
  noise.noise = 0.2;
  EXPECT_LT(AnalyzeTone(kCases[2], noise).total_probability(), 0.2);
}

TEST(YinAnalyzer, RejectsInvalidOptions) {
  YinOptions o;
  o.min_f0_hz = 500;
  o.max_f0_hz = 100;
  EXPECT_THROW(YinAnalyzer{o}, std::invalid_argument);
  o = YinOptions();
  o.max_f0_hz = o.sample_rate_hz;  // above rate / 4
  EXPECT_THROW(YinAnalyzer{o}, std::invalid_argument);
  o = YinOptions();
  o.sample_rate_hz = 0;
  EXPECT_THROW(YinAnalyzer{o}, std::invalid_argument);
}

}  // namespace
}  // namespace arco::audio
