#include "arco/audio/align.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace arco::audio {
namespace {

// Music-like sound as a function of continuous time, so a copy on another clock is
// exact: bowed-string-like notes (6 harmonics, 30 ms attack, slow decay, 5.5 Hz
// vibrato) one after another with small gaps, and short noise-like bursts (inharmonic
// partials) at some onsets, as a bow change sounds.
struct Note {
  double onset_s, length_s, f0_hz, amplitude;
  bool burst;
  double phases[6];
};

std::vector<Note> Score(double duration_s, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Note> notes;
  for (double t = 0.05; t < duration_s;) {
    Note n;
    n.onset_s = t;
    n.length_s = 0.15 + 0.6 * u(rng);
    n.f0_hz = 196.0 * std::pow(2.0, std::floor(30 * u(rng)) / 12.0);
    n.amplitude = 0.05 + 0.15 * u(rng);
    n.burst = u(rng) < 0.4;
    for (double& p : n.phases) p = 2 * M_PI * u(rng);
    notes.push_back(n);
    t += n.length_s + 0.02 + 0.1 * u(rng);
  }
  return notes;
}

// Samples of the score at times offset_s + (1 + drift_ppm 1e-6) n / rate_hz (the
// reference clock seen from a device that started at offset_s and runs slow by
// drift_ppm), plus white noise at `noise_rms`.
std::vector<float> Render(const std::vector<Note>& notes,
                          double duration_s,
                          int rate_hz,
                          double offset_s,
                          double drift_ppm,
                          double noise_rms,
                          uint32_t noise_seed) {
  const int64_t count = static_cast<int64_t>(duration_s * rate_hz);
  std::vector<double> out(static_cast<size_t>(count), 0.0);
  const double scale = 1.0 + drift_ppm * 1e-6;
  for (const Note& n : notes) {
    // Samples whose reference time falls in the note.
    const double first = (n.onset_s - offset_s) / scale * rate_hz;
    const double last = (n.onset_s + n.length_s + 0.3 - offset_s) / scale * rate_hz;
    const int64_t i0 = std::max<int64_t>(0, static_cast<int64_t>(std::ceil(first)));
    const int64_t i1 = std::min<int64_t>(count - 1, static_cast<int64_t>(std::floor(last)));
    for (int64_t i = i0; i <= i1; ++i) {
      const double t = offset_s + scale * double(i) / rate_hz - n.onset_s;
      if (t < 0) continue;
      double env = std::min(1.0, t / 0.03) * std::exp(-t / 1.5);
      if (t > n.length_s) env *= std::exp(-(t - n.length_s) / 0.05);  // release
      const double vib = 0.004 * std::sin(2 * M_PI * 5.5 * t);
      double v = 0;
      for (int h = 1; h <= 6; ++h) {
        v += std::sin(2 * M_PI * n.f0_hz * h * (t + vib / (2 * M_PI * 5.5)) + n.phases[h - 1]) / h;
      }
      if (n.burst && t < 0.04) {
        for (int h = 0; h < 6; ++h) {
          v += 0.8 * std::sin(2 * M_PI * (900 + 517.3 * h * h) * t + n.phases[h]) * (1 - t / 0.04);
        }
      }
      out[static_cast<size_t>(i)] += n.amplitude * env * v;
    }
  }
  std::mt19937 rng(noise_seed);
  std::normal_distribution<double> noise(0.0, noise_rms);
  std::vector<float> samples(out.size());
  for (size_t i = 0; i < out.size(); ++i) samples[i] = static_cast<float>(out[i] + noise(rng));
  return samples;
}

AudioTrack Track(std::string name, std::vector<float> samples, int rate_hz) {
  AudioTrack t;
  t.source = std::move(name);
  t.rate_hz = rate_hz;
  t.samples = std::move(samples);
  return t;
}

constexpr int kRate = 16000;

TEST(AlignTracks, RecoversSubSampleOffsetsWithinATenthOfAMillisecond) {
  const std::vector<Note> notes = Score(40, 7);
  const AudioTrack ref = Track("ref", Render(notes, 25, kRate, 0.0, 0, 0.003, 1), kRate);
  int seed = 2;
  for (double offset : {0.1234, 0.35, 1.1, -0.5678 + 1.0, 3.21987}) {
    const AudioTrack other =
        Track("other", Render(notes, 20, kRate, offset, 0, 0.003, seed++), kRate);
    const auto r = AlignTracks(ref, other, AlignOptions{});
    ASSERT_TRUE(r.ok()) << r.status().message();
    EXPECT_NEAR(r->offset_s, offset, 1e-4) << offset;
    EXPECT_EQ(r->drift_ppm, 0.0) << "a 20 s take estimates no drift";
    EXPECT_GT(r->confidence, 0.5);
    EXPECT_GE(r->windows_used, 3);
  }
}

TEST(AlignTracks, NegativeOffsetWhenTheOtherStartedFirst) {
  const std::vector<Note> notes = Score(30, 11);
  const AudioTrack ref = Track("ref", Render(notes, 15, kRate, 0.75, 0, 0.002, 1), kRate);
  const AudioTrack other = Track("other", Render(notes, 20, kRate, 0.0, 0, 0.002, 2), kRate);
  const auto r = AlignTracks(ref, other, AlignOptions{});
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_NEAR(r->offset_s, -0.75, 1e-4);
}

TEST(AlignTracks, EstimatesClockDriftOverTheTake) {
  const std::vector<Note> notes = Score(130, 3);
  const AudioTrack ref = Track("ref", Render(notes, 125, kRate, 0.0, 0, 0.003, 1), kRate);
  for (double drift : {30.0, -45.0}) {
    const AudioTrack other =
        Track("other", Render(notes, 120, kRate, 0.4321, drift, 0.003, 5), kRate);
    const auto r = AlignTracks(ref, other, AlignOptions{});
    ASSERT_TRUE(r.ok()) << r.status().message();
    EXPECT_NEAR(r->offset_s, 0.4321, 1e-4) << drift;
    EXPECT_NEAR(r->drift_ppm, drift, 2.0);
    // The reference time of the other's last second, which 30 ppm moves by 3.6 ms.
    const double t_ref = r->offset_s + (1 + r->drift_ppm * 1e-6) * 119.0;
    EXPECT_NEAR(t_ref, 0.4321 + (1 + drift * 1e-6) * 119.0, 1e-4);
  }
}

TEST(AlignTracks, NoisyCopyStillWithinAMillisecond) {
  const std::vector<Note> notes = Score(30, 21);
  const AudioTrack ref = Track("ref", Render(notes, 20, kRate, 0.0, 0, 0.01, 1), kRate);
  // Noise at about -20 dB below the music.
  const AudioTrack other = Track("other", Render(notes, 18, kRate, 0.987, 0, 0.03, 9), kRate);
  const auto r = AlignTracks(ref, other, AlignOptions{});
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_NEAR(r->offset_s, 0.987, 1e-3);
}

TEST(AlignTracks, PeriodicSoundIsAmbiguous) {
  // A metronome: the same click every 0.5 s matches at every multiple of 0.5 s, whatever
  // the click's pitch and whichever recording is longer.
  for (double click_hz : {1000.0, 2000.0}) {
    std::vector<float> clicks(static_cast<size_t>(12 * kRate), 0.0f);
    for (int64_t beat = 0; beat < 24; ++beat) {
      for (int i = 0; i < 400; ++i) {
        clicks[static_cast<size_t>(beat * kRate / 2 + i)] = static_cast<float>(
            0.5 * std::sin(2 * M_PI * click_hz * i / kRate) * std::exp(-i / 80.0));
      }
    }
    for (double other_s : {7.0, 8.0, 11.0}) {
      const AudioTrack ref =
          Track("ref.wav", std::vector<float>(clicks.begin(), clicks.begin() + 8 * kRate), kRate);
      const int64_t first = 3 * kRate / 10;
      const AudioTrack other =
          Track("other.wav",
                std::vector<float>(clicks.begin() + first,
                                   clicks.begin() + first + static_cast<int64_t>(other_s * kRate)),
                kRate);
      const auto r = AlignTracks(ref, other, AlignOptions{});
      ASSERT_FALSE(r.ok()) << click_hz << " Hz, " << other_s << " s: offset " << r->offset_s
                           << " confidence " << r->confidence;
      EXPECT_NE(r.status().message().find("ambiguous"), std::string::npos) << r.status().message();
      EXPECT_NE(r.status().message().find("other.wav"), std::string::npos);
    }
  }
}

TEST(AlignTracks, SilenceIsAnError) {
  const std::vector<Note> notes = Score(20, 5);
  const AudioTrack ref = Track("ref.wav", Render(notes, 10, kRate, 0, 0, 0.001, 1), kRate);
  const AudioTrack silent = Track("silent.wav", std::vector<float>(10 * kRate, 0.0f), kRate);
  const auto r = AlignTracks(ref, silent, AlignOptions{});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("silent.wav: the audio track is silent"), std::string::npos)
      << r.status().message();
}

TEST(AlignTracks, UnrelatedRecordingsAreAnError) {
  const AudioTrack a = Track("a.wav", Render(Score(20, 1), 15, kRate, 0, 0, 0.003, 1), kRate);
  const AudioTrack b = Track("b.wav", Render(Score(20, 2), 15, kRate, 0, 0, 0.003, 2), kRate);
  const auto r = AlignTracks(a, b, AlignOptions{});
  EXPECT_FALSE(r.ok()) << "offset " << r->offset_s << " confidence " << r->confidence;
}

TEST(AlignOptions, RejectsInvalidValues) {
  EXPECT_TRUE(AlignOptions{}.Validate().ok());
  AlignOptions o;
  o.window_s = 0.1;
  EXPECT_FALSE(o.Validate().ok());
  o = AlignOptions{};
  o.fine_rate_hz = 1000;
  EXPECT_FALSE(o.Validate().ok());
  o = AlignOptions{};
  o.ambiguous_ratio = 1.5;
  EXPECT_FALSE(o.Validate().ok());
  o = AlignOptions{};
  o.max_drift_ppm = -1;
  EXPECT_FALSE(o.Validate().ok());
}

}  // namespace
}  // namespace arco::audio
