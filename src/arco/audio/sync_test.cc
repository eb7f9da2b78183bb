// Audio/video sync on generated media with a flash and a click at known times.
#include "arco/audio/sync.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "arco/audio/audio_reader.h"
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
  EXPECT_GT(sync->confidence, 0.5);
  EXPECT_TRUE(sync->warnings.empty());
  // Without --audio-near-s two clicks of nearly equal strength (the decoy is 1.6 dB
  // stronger) are ambiguous: an error that names both, not the decoy's offset.
  options.audio_near_s = NAN;
  auto wrong = SyncAudioToVideo(audio_path, video_path, options);
  ASSERT_FALSE(wrong.ok());
  EXPECT_NE(wrong.status().message().find("ambiguous sound event"), std::string::npos)
      << wrong.status().message();
  EXPECT_NE(wrong.status().message().find("8.000 s"), std::string::npos);
  EXPECT_NE(wrong.status().message().find("3.100 s"), std::string::npos);
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

// The clap scenes of issue 11, all meeting at kContactS (3 s) in 5 s of 30 fps video.
// Tolerance, from first principles: the contact model (sync.h) is exact for hands at
// constant speed whose motion energy is proportional to their image shift (edges of
// uniform hands). Texture breaks the proportionality once the shift per frame nears the
// texture's scale: stripes 5 px apart shifting 2.5 px per frame put relatively more
// energy into the partly moving frames, which makes the fast clap 0.18 frame late
// (measured); 8-bit rounding and sensor noise add a few hundredths. So 0.25 frame,
// inside the half a frame that decides which frame shows the contact. Timing the
// start of the motion instead (the old behaviour) is 11 frames early for the fast clap
// and 40 for the slow one.
constexpr double kContactS = 3.0;
constexpr double kClapToleranceS = 0.25 / 30.0;

testing::ClapScene ConstantSpeedClap() {
  testing::ClapScene scene;
  scene.contact_s = kContactS;
  scene.speed_px_s = 150;  // hands 54 px apart start moving 0.36 s before contact
  scene.start_gap_px = 54;
  scene.hand_stripes_grey = 40;
  return scene;
}
testing::ClapScene SlowClap() {
  testing::ClapScene scene = ConstantSpeedClap();
  scene.speed_px_s = 40;  // 1.35 s of motion, 1.3 px per frame
  return scene;
}
// The same clap four times farther from the camera: a quarter of the size and speed.
testing::ClapScene FarClap() {
  testing::ClapScene scene = ConstantSpeedClap();
  scene.hand_width_px = 25.0 / 4;
  scene.hand_height_px = 40.0 / 4;
  scene.start_gap_px = 54.0 / 4;
  scene.speed_px_s = 150.0 / 4;
  scene.center_x_px = 110;
  scene.center_y_px = 35;
  return scene;
}

double ClapTime(const testing::ClapScene& scene, const std::string& name) {
  const std::string path = testing::TempPath(name + ".mkv");
  EXPECT_TRUE(testing::WriteTestVideo(path, testing::ClapVideo(scene, 150)).ok());
  auto event = FindVideoEvent(path, SyncOptions(), nullptr);
  EXPECT_TRUE(event.ok()) << name << ": " << event.status().message();
  return event.ok() ? event->time_s : NAN;
}

TEST(FindVideoEvent, ClapIsTimedWhenTheHandsMeetNotWhenTheyStartMoving) {
  // Contact at several phases inside a frame's exposure.
  for (double shift_frames : {0.0, 0.27, 0.5, 0.81}) {
    const double contact_s = kContactS + shift_frames / 30.0;
    auto fast = ConstantSpeedClap(), slow = SlowClap(), far = FarClap();
    fast.contact_s = slow.contact_s = far.contact_s = contact_s;
    EXPECT_NEAR(ClapTime(fast, "fast_clap"), contact_s, kClapToleranceS) << shift_frames;
    EXPECT_NEAR(ClapTime(slow, "slow_clap"), contact_s, kClapToleranceS) << shift_frames;
    EXPECT_NEAR(ClapTime(far, "far_clap"), contact_s, kClapToleranceS) << shift_frames;
    auto noisy = fast;
    noisy.noise_grey = 3;  // sensor noise: the drop still stands far above the jitter
    EXPECT_NEAR(ClapTime(noisy, "noisy_clap"), contact_s, kClapToleranceS) << shift_frames;
  }
}

TEST(FindVideoEvent, StillVideoHasNoEvent) {
  for (double noise : {0.0, 3.0}) {
    testing::ClapScene still = ConstantSpeedClap();
    still.contact_s = 100;  // the hands never move inside the video
    still.noise_grey = noise;
    const std::string path = testing::TempPath("still.mkv");
    ASSERT_TRUE(testing::WriteTestVideo(path, testing::ClapVideo(still, 150)).ok());
    for (VideoEvent kind : {VideoEvent::kClap, VideoEvent::kFlash}) {
      SyncOptions options;
      options.video_event = kind;
      auto event = FindVideoEvent(path, options, nullptr);
      ASSERT_FALSE(event.ok()) << noise << ": found an event at " << event->time_s;
      const std::string& m = event.status().message();
      EXPECT_NE(m.find(kind == VideoEvent::kClap ? "no clap" : "no flash"), std::string::npos) << m;
      EXPECT_NE(m.find("motion energy peak"), std::string::npos) << m;
      EXPECT_NE(m.find("background"), std::string::npos) << m;
    }
  }
}

// Two pairs of hands, one in the top half clapping at top_s, one in the bottom half
// at bottom_s.
testing::TestVideo TwoClaps(double top_s, double bottom_s) {
  testing::ClapScene top = ConstantSpeedClap(), bottom = ConstantSpeedClap();
  top.contact_s = top_s;
  top.center_y_px = 30;
  bottom.contact_s = bottom_s;
  bottom.center_y_px = 90;
  testing::TestVideo video;
  video.frames = 180;
  video.draw = [=](int k, std::vector<double>* grey) {
    std::vector<double> lower;
    testing::DrawClapFrame(top, 30, k, 160, 120, grey);
    testing::DrawClapFrame(bottom, 30, k, 160, 120, &lower);
    std::copy(lower.begin() + 60 * 160, lower.end(), grey->begin() + 60 * 160);
  };
  return video;
}

TEST(FindVideoEvent, TwoEqualClapsAreAmbiguousUnlessAWindowSeparatesThem) {
  const std::string path = testing::TempPath("two_claps.mkv");
  ASSERT_TRUE(testing::WriteTestVideo(path, TwoClaps(2.0, 4.0)).ok());
  auto event = FindVideoEvent(path, SyncOptions(), nullptr);
  ASSERT_FALSE(event.ok()) << "found " << event->time_s;
  const std::string& m = event.status().message();
  EXPECT_NE(m.find("ambiguous clap"), std::string::npos) << m;
  EXPECT_NE(m.find("video_near_s"), std::string::npos) << m;
  SyncOptions near;
  near.video_near_s = 4.0;
  near.search_s = 1.0;
  auto second = FindVideoEvent(path, near, nullptr);
  ASSERT_TRUE(second.ok()) << second.status().message();
  EXPECT_NEAR(second->time_s, 4.0, kClapToleranceS);
}

TEST(SyncAudioToVideo, SilenceAndAStillVideoIsAnErrorWithTheEvidence) {
  const std::string wav = testing::TempPath("silence.wav");
  ASSERT_TRUE(testing::WriteWav(wav, std::vector<float>(5 * 48000, 0.0f), 48000).ok());
  testing::ClapScene still = ConstantSpeedClap();
  still.contact_s = 100;
  const std::string mkv = testing::TempPath("still_take.mkv");
  ASSERT_TRUE(testing::WriteTestVideo(mkv, testing::ClapVideo(still, 150)).ok());
  auto sync = SyncAudioToVideo(wav, mkv, SyncOptions());
  ASSERT_FALSE(sync.ok()) << "offset " << sync->offset_s;
  const std::string& m = sync.status().message();
  EXPECT_NE(m.find("no sound event"), std::string::npos) << m;
  EXPECT_NE(m.find("dBFS vs noise floor"), std::string::npos) << m;
  // With a click the audio is fine, and the still video is the error.
  const std::string click = testing::TempPath("click_take.wav");
  ASSERT_TRUE(testing::WriteWav(click, ClickTrack(5.0, 2.0, 48000), 48000).ok());
  auto still_video = SyncAudioToVideo(click, mkv, SyncOptions());
  ASSERT_FALSE(still_video.ok());
  EXPECT_NE(still_video.status().message().find("no clap"), std::string::npos);
}

TEST(SyncAudioToVideos, SeveralCamerasAgreeOnOneOffset) {
  // The recorder started 2.2 s before the cameras: the clap sounds at 5.2 s.
  const std::string wav = testing::TempPath("rig.wav");
  ASSERT_TRUE(testing::WriteWav(wav, ClickTrack(9.0, kContactS + 2.2, 48000), 48000).ok());
  std::vector<SyncView> views;
  int i = 0;
  for (const testing::ClapScene& scene : {ConstantSpeedClap(), FarClap(), SlowClap()}) {
    testing::ClapScene noisy = scene;
    noisy.noise_grey = 2;
    noisy.seed = 10 + i;
    const std::string path = testing::TempPath("rig" + std::to_string(i++) + ".mkv");
    ASSERT_TRUE(testing::WriteTestVideo(path, testing::ClapVideo(noisy, 150)).ok());
    views.push_back({path, nullptr});
  }
  // A fourth camera sees nothing: left out with a warning.
  testing::ClapScene away = ConstantSpeedClap();
  away.contact_s = 100;
  const std::string blind = testing::TempPath("rig_blind.mkv");
  ASSERT_TRUE(testing::WriteTestVideo(blind, testing::ClapVideo(away, 150)).ok());
  views.push_back({blind, nullptr});
  auto sync = SyncAudioToVideos(wav, views, SyncOptions());
  ASSERT_TRUE(sync.ok()) << sync.status().message();
  ASSERT_EQ(sync->views.size(), 4u);
  for (int v = 0; v < 3; ++v) {
    EXPECT_TRUE(sync->views[v].used) << v;
    EXPECT_NEAR(sync->views[v].event.time_s, kContactS, kClapToleranceS) << v;
  }
  EXPECT_FALSE(sync->views[3].used);
  EXPECT_NE(sync->views[3].error.find("no clap"), std::string::npos);
  ASSERT_EQ(sync->warnings.size(), 1u);
  EXPECT_NE(sync->warnings[0].find("rig_blind.mkv"), std::string::npos);
  // The click is timed within a millisecond, the mean of three views within the tolerance.
  EXPECT_NEAR(sync->offset_s, 2.2, 0.001 + kClapToleranceS);
  EXPECT_GT(sync->confidence, 0.9);
  // A camera whose frames are numbered 10 frames later (its mapping) disagrees by
  // 10 frames: two views that disagree are an error.
  views.resize(2);
  views[1].global_frame = [](double frame) { return frame + 10; };
  auto disagree = SyncAudioToVideos(wav, views, SyncOptions());
  ASSERT_FALSE(disagree.ok());
  EXPECT_NE(disagree.status().message().find("disagree"), std::string::npos)
      << disagree.status().message();
  // A frame rate given for 30 fps videos: their own (within 0.1 %) is fine, another one
  // would scale every video time, so it is an error naming the video (not a view left
  // out).
  views[1].global_frame = nullptr;
  SyncOptions same;
  same.video_fps = 30.01;
  EXPECT_TRUE(SyncAudioToVideos(wav, views, same).ok());
  SyncOptions half;
  half.video_fps = 15;
  auto wrong = SyncAudioToVideos(wav, views, half);
  ASSERT_FALSE(wrong.ok());
  EXPECT_EQ(wrong.status().message(),
            views[0].video +
                ": 30 fps in the container, but video_fps = 15 (video_fps sets the rate of "
                "image folders only; leave it out)");
}

TEST(SyncAudioToVideo, ConfidenceFallsAndWarnsWithAComparableSecondOnset) {
  testing::ClapScene scene = ConstantSpeedClap();
  const std::string mkv = testing::TempPath("conf.mkv");
  ASSERT_TRUE(testing::WriteTestVideo(mkv, testing::ClapVideo(scene, 150)).ok());
  auto audio = ClickTrack(9.0, 4.0, 48000);
  const std::string clean = testing::TempPath("conf_clean.wav");
  ASSERT_TRUE(testing::WriteWav(clean, audio, 48000).ok());
  auto sure = SyncAudioToVideo(clean, mkv, SyncOptions());
  ASSERT_TRUE(sure.ok()) << sure.status().message();
  EXPECT_GT(sure->confidence, 0.9);
  EXPECT_TRUE(sure->warnings.empty());
  // A second click at 0.35 of the amplitude (its onset measures about 5 dB below the
  // first's): the audio's distinctness falls below 0.5, and the offset comes with a
  // warning.
  const auto second = ClickTrack(9.0, 7.0, 48000);
  for (size_t i = 0; i < audio.size(); ++i) audio[i] += 0.35f * second[i];
  const std::string doubled = testing::TempPath("conf_two.wav");
  ASSERT_TRUE(testing::WriteWav(doubled, audio, 48000).ok());
  auto unsure = SyncAudioToVideo(doubled, mkv, SyncOptions());
  ASSERT_TRUE(unsure.ok()) << unsure.status().message();
  EXPECT_NEAR(unsure->offset_s, 1.0, 0.001 + kClapToleranceS);
  EXPECT_LT(unsure->confidence, kSyncLowConfidence);
  ASSERT_FALSE(unsure->warnings.empty());
  EXPECT_NE(unsure->warnings[0].find("low confidence"), std::string::npos);
}

// The SPD cello recordings (../shared/data/spd) hold music and no clap: no event,
// not a bow change taken for one. The same music with a clap added (20 ms of broadband
// noise decaying with 3 ms, 0.9 of full scale: a clap near the recorder, 9.5 s in,
// while the cello plays) gives the clap.
TEST(FindAudioOnset, RealCelloRecordingsHaveNoClapUntilOneIsAdded) {
  for (const char* name : {"background.wav", "pgy.wav"}) {
    const std::string path = std::string(ARCO_SHARED_DATA_DIR) + "/spd/" + name;
    auto none = FindAudioOnset(path, SyncOptions());
    ASSERT_FALSE(none.ok()) << name << ": an event at " << none->time_s;
    EXPECT_NE(none.status().message().find("no sound event"), std::string::npos)
        << none.status().message();
    auto reader = OpenAudio(path);
    ASSERT_TRUE(reader.ok());
    const int rate = (*reader)->info().sample_rate_hz;
    std::vector<float> music(static_cast<size_t>(30 * rate));
    auto got = (*reader)->ReadMono(music.data(), static_cast<int64_t>(music.size()));
    ASSERT_TRUE(got.ok());
    music.resize(static_cast<size_t>(*got));
    std::mt19937 rng(9);
    std::normal_distribution<double> gauss(0.0, 1.0);
    const int64_t at = std::llround(9.5 * rate);
    for (int i = 0; i < rate / 50; ++i) {  // 20 ms of noise decaying with 3 ms
      music[at + i] += static_cast<float>(0.9 * std::exp(-i / (0.003 * rate)) * gauss(rng));
    }
    const std::string with_clap = testing::TempPath(std::string("clap_") + name);
    ASSERT_TRUE(testing::WriteWav(with_clap, music, rate).ok());
    auto found = FindAudioOnset(with_clap, SyncOptions());
    ASSERT_TRUE(found.ok()) << name << ": " << found.status().message();
    EXPECT_NEAR(found->time_s, 9.5, 0.001) << name;
  }
}

}  // namespace
}  // namespace arco::audio
