// Audio/video sync on generated media with a flash and a click at known times.
#include "arco/audio/sync.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "arco/audio/pitch_tracker.h"
#include "arco/audio/test_media.h"
#include "arco/audio/test_signals.h"

namespace arco::audio {
namespace {

// Frame k shows the exposure [(k - 1/2)/fps, (k + 1/2)/fps): the lit fraction
// of a light on from on_s to off_s.
double LitFraction(int k, double fps, double on_s, double off_s) {
  const double a = (k - 0.5) / fps, b = (k + 0.5) / fps;
  return std::max(0.0, std::min(b, off_s) - std::max(a, on_s)) * fps;
}

// Quiet noise with a click (a 2 ms decaying broadband burst) at click_s.
std::vector<float> ClickTrack(double seconds, double click_s, int rate) {
  std::vector<float> x(static_cast<size_t>(seconds * rate));
  std::mt19937 rng(5);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (auto& v : x) v = static_cast<float>(0.002 * gauss(rng));
  const int64_t at = std::llround(click_s * rate);
  for (int i = 0; i < rate / 500 && at + i < static_cast<int64_t>(x.size()); ++i) {
    x[at + i] += static_cast<float>(0.8 * std::exp(-i / (rate * 0.0005)) * gauss(rng));
  }
  return x;
}

TEST(FindVideoEvent, FlashTimedBelowATenthOfAFrame) {
  for (double on_s : {1.2345, 1.0, 2.0 + 0.5 / 30.0, 0.71}) {
    testing::TestVideo video;
    video.frames = 100;
    video.brightness = [&](int k) { return 40.0 + 150.0 * LitFraction(k, 30.0, on_s, on_s + 0.2); };
    const std::string path = testing::TempPath("flash.mkv");
    ASSERT_TRUE(testing::WriteTestVideo(path, video).ok());
    double fps = 0;
    SyncOptions flash;
    flash.video_event = VideoEvent::kFlash;
    auto event = FindVideoEvent(path, flash, &fps);
    ASSERT_TRUE(event.ok()) << event.status().message();
    EXPECT_DOUBLE_EQ(fps, 30.0);
    EXPECT_NEAR(event->time_s, on_s, 0.1 / 30.0) << on_s;
  }
}

// Two bright hands close at constant speed (or accelerating) and stop at
// contact_s; each frame integrates its exposure (16 sub-samples), as a camera
// with an open shutter does.
void DrawClap(int k, double contact_s, bool accelerate, std::vector<double>* grey) {
  const int w = 160, h = 120;
  std::fill(grey->begin(), grey->end(), 30.0);
  for (int sub = 0; sub < 16; ++sub) {
    const double t = (k - 0.5 + (sub + 0.5) / 16.0) / 30.0;
    const double before = std::max(0.0, contact_s - t);  // seconds until contact
    // Accelerating: speed grows from 10 px/s at 0.4 s before contact to 250 px/s.
    const double b = std::min(before, 0.4);
    const double gap =
        accelerate ? 250.0 * b - 300.0 * b * b + 10.0 * (before - b) : 150.0 * before;  // px
    const double left_edge = 80.0 - gap / 2.0;  // right edge of the left hand
    for (int y = 40; y < 80; ++y) {
      for (int x = 0; x < w; ++x) {
        const double left = std::clamp(left_edge - x, 0.0, 1.0) * (x >= left_edge - 25.0);
        const double right =
            std::clamp(x + 1 - (160.0 - left_edge), 0.0, 1.0) * (x < 160.0 - left_edge + 25.0);
        (*grey)[static_cast<size_t>(y) * w + x] += 200.0 / 16.0 * std::min(1.0, left + right);
      }
    }
  }
  (void)h;
}

TEST(FindVideoEvent, ClapContactTimedBelowAFrame) {
  for (bool accelerate : {false, true}) {
    for (double contact_s : {1.3137, 1.5, 1.6833}) {
      testing::TestVideo video;
      video.frames = 75;
      video.draw = [&](int k, std::vector<double>* grey) {
        DrawClap(k, contact_s, accelerate, grey);
      };
      const std::string path = testing::TempPath("clap.mkv");
      ASSERT_TRUE(testing::WriteTestVideo(path, video).ok());
      auto event = FindVideoEvent(path, SyncOptions(), nullptr);
      ASSERT_TRUE(event.ok()) << event.status().message();
      // Constant speed: exact up to pixel quantisation; accelerating hands are
      // timed a little late (the model assumes constant speed).
      EXPECT_NEAR(event->time_s, contact_s, (accelerate ? 0.25 : 0.15) / 30.0)
          << contact_s << (accelerate ? " accelerating" : " constant speed");
    }
  }
}

TEST(FindAudioOnset, ClickWithinAMillisecond) {
  for (double click_s : {0.8, 2.5123, 7.0}) {
    const std::string path = testing::TempPath("click.wav");
    ASSERT_TRUE(testing::WriteWav(path, ClickTrack(9.0, click_s, 44100), 44100).ok());
    auto event = FindAudioOnset(path, SyncOptions());
    ASSERT_TRUE(event.ok()) << event.status().message();
    EXPECT_NEAR(event->time_s, click_s, 0.001);
    EXPECT_GT(event->strength, 20.0);
  }
}

TEST(SyncAudioToVideo, RecoversTheOffsetAndTheNearOptionPicksAnEvent) {
  // Video: flash at 1.2345 s. Audio recorder started earlier: click at 3.1 s,
  // plus a louder decoy click at 8.0 s that --audio-near-s must skip.
  const double flash_s = 1.2345, click_s = 3.1;
  testing::TestVideo video;
  video.frames = 120;
  video.brightness = [&](int k) { return 40.0 + 150.0 * LitFraction(k, 30.0, flash_s, 1.5); };
  const std::string video_path = testing::TempPath("take.mkv");
  ASSERT_TRUE(testing::WriteTestVideo(video_path, video).ok());
  auto audio = ClickTrack(10.0, click_s, 48000);
  const auto decoy = ClickTrack(10.0, 8.0, 48000);
  for (size_t i = 0; i < audio.size(); ++i) audio[i] += 1.2f * decoy[i];
  const std::string audio_path = testing::TempPath("take.wav");
  ASSERT_TRUE(testing::WriteWav(audio_path, audio, 48000).ok());
  SyncOptions options;
  options.video_event = VideoEvent::kFlash;
  options.audio_near_s = 3.0;
  auto sync = SyncAudioToVideo(audio_path, video_path, options);
  ASSERT_TRUE(sync.ok()) << sync.status().message();
  EXPECT_NEAR(sync->offset_s, click_s - flash_s, 0.001 + 0.1 / 30.0);
  EXPECT_EQ(sync->video.frame, 37);
  options.audio_near_s = NAN;
  auto wrong = SyncAudioToVideo(audio_path, video_path, options);
  ASSERT_TRUE(wrong.ok());
  EXPECT_NEAR(wrong->audio.time_s, 8.0, 0.001);  // the decoy is the strongest overall
}

TEST(TrackPitch, ReadsTheAudioTrackOfAVideo) {
  for (const char* codec : {"pcm_s16le", "aac"}) {
    testing::TestVideo video;
    video.frames = 60;
    testing::ToneOptions tone;
    tone.sample_rate_hz = 48000;
    tone.harmonics = 5;
    video.audio = testing::RenderTone([](double) { return 220.0; }, 2.0, tone);
    video.audio_codec = codec;
    const std::string path = testing::TempPath(std::string("tone_") + codec + ".mkv");
    ASSERT_TRUE(testing::WriteTestVideo(path, video).ok()) << codec;
    PitchTrackerOptions o;
    o.range = *InstrumentRangeByName("cello");
    PitchSummary summary;
    auto track = TrackPitchFile(path, o, &summary);
    ASSERT_TRUE(track.ok()) << track.status().message();
    EXPECT_NE(summary.source_format.find("ffmpeg"), std::string::npos);
    EXPECT_NEAR(summary.duration_s, 2.0, 0.03) << codec;
    int voiced = 0;
    for (const auto& f : track->frames) {
      if (f.time_s < 0.2 || f.time_s > 1.8) continue;
      ASSERT_TRUE(f.voiced) << codec << " " << f.time_s;
      EXPECT_NEAR(1200 * std::log2(f.f0_hz / 220.0), 0.0, 2.0) << codec;
      ++voiced;
    }
    EXPECT_GT(voiced, 40);
  }
}

TEST(Sync, BadInputsAreErrors) {
  const std::string wav = testing::TempPath("only_audio.wav");
  ASSERT_TRUE(testing::WriteWav(wav, ClickTrack(1.0, 0.5, 16000), 16000).ok());
  auto v = FindVideoEvent(wav, SyncOptions(), nullptr);
  ASSERT_FALSE(v.ok());
  EXPECT_NE(v.status().message().find("no video stream"), std::string::npos);
  EXPECT_FALSE(FindVideoEvent("/nonexistent.mp4", SyncOptions(), nullptr).ok());
  EXPECT_FALSE(FindAudioOnset("/nonexistent.wav", SyncOptions()).ok());
  SyncOptions bad;
  bad.search_s = -1;
  EXPECT_FALSE(bad.Validate().ok());
  // A video without audio: pitch reports one clear error.
  testing::TestVideo silent_video;
  const std::string mkv = testing::TempPath("no_audio.mkv");
  ASSERT_TRUE(testing::WriteTestVideo(mkv, silent_video).ok());
  PitchTrackerOptions o;
  o.range = *InstrumentRangeByName("cello");
  auto track = TrackPitchFile(mkv, o, nullptr);
  ASSERT_FALSE(track.ok());
  EXPECT_NE(track.status().message().find("no audio stream"), std::string::npos)
      << track.status().message();
}

}  // namespace
}  // namespace arco::audio
