// The sound-corrected reference: contour interpolation and the tau mapping
// under pitch bends (the harmonic-peak fit itself: harmonic_fit_test.cc).
#include "arco/audio/sound_truth.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "arco/audio/test_music.h"
#include "arco/audio/test_signals.h"

namespace arco::audio::testing {
namespace {

double Cents(double f, double truth) { return 1200.0 * std::log2(f / truth); }

TEST(KeyContour, InterpolatesAndPropagatesGaps) {
  KeyContour c;
  c.step_s = 0.01;
  c.cents = {0.0, 10.0, std::nan(""), 30.0};
  EXPECT_DOUBLE_EQ(c.At(0.005), 5.0);
  EXPECT_TRUE(std::isnan(c.At(0.015)));
  EXPECT_TRUE(std::isnan(c.At(0.025)));
  EXPECT_DOUBLE_EQ(c.At(0.03), 30.0);
  EXPECT_TRUE(std::isnan(c.At(0.031)));
  EXPECT_TRUE(std::isnan(c.At(-0.001)));
}

TEST(SoundTruth, CorrectsTheScoreByTheContourAtSampleTime) {
  TestMusic music;
  music.instrument = "cello";
  MidiTrack track;
  track.notes.push_back({1.0, 2.0, 57, 90});  // A3 = 220 Hz
  track.bends.push_back({1.0, 0.0});
  track.bends.push_back({1.5, 2.0});  // +2 semitones from 1.5 s: sample runs 2^(2/12) faster
  music.midi.tracks.push_back(track);
  music.duration_s = 3.0;
  KeyContour contour;  // the sample drifts up 1 cent per 10 ms
  for (int i = 0; i <= 150; ++i) contour.cents.push_back(i * 1.0);
  music.key_contours[57] = contour;
  const double lat = kFluidsynthLatencyS;
  // Before the bend: tau = t - onset.
  EXPECT_NEAR(Cents(music.SoundF0Hz(1.3 + lat), 220.0), 30.0, 1e-6);
  // After it: tau = 0.5 + 2^(2/12) (t - 1.5), on top of the bent score.
  const double tau = 0.5 + std::exp2(2.0 / 12.0) * 0.2;
  EXPECT_NEAR(Cents(music.SoundF0Hz(1.7 + lat), 220.0), 200.0 + 100.0 * tau, 1e-6);
  EXPECT_EQ(music.SoundF0Hz(2.5), 0.0);  // not voiced
  music.key_contours.clear();
  EXPECT_EQ(music.SoundF0Hz(1.3 + lat), 0.0);  // no contour: not scored
}

}  // namespace
}  // namespace arco::audio::testing
