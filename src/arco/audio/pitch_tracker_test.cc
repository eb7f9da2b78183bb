// End-to-end tracking: frame timing, drift, vibrato, glides, silence, real cello.
#include "arco/audio/pitch_tracker.h"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "arco/audio/test_signals.h"
#include "arco/util/file_io.h"

namespace arco::audio {
namespace {

double Cents(double f, double truth) { return 1200.0 * std::log2(f / truth); }

PitchTrackerOptions Options(const std::string& instrument, double fps = 30.0) {
  PitchTrackerOptions o;
  o.range = *InstrumentRangeByName(instrument);
  o.fps = fps;
  return o;
}

PitchTrack Track(const std::string& path,
                 const PitchTrackerOptions& o,
                 PitchSummary* summary = nullptr) {
  PitchSummary local;
  auto track = TrackPitchFile(path, o, summary ? summary : &local);
  EXPECT_TRUE(track.ok()) << track.status().message();
  return track.ok() ? *track : PitchTrack();
}

std::string WriteTone(const std::string& name,
                      const testing::F0Function& f0,
                      double seconds,
                      testing::ToneOptions tone = {}) {
  const std::string path = testing::TempPath(name);
  EXPECT_TRUE(
      testing::WriteWav(path, testing::RenderTone(f0, seconds, tone), tone.sample_rate_hz).ok());
  return path;
}

// Progress goes through arco::Progress: one total of kPitchProgressSteps, advanced in
// steps that never pass it.
TEST(TrackPitch, ReportsProgressThroughTheOneInterface) {
  struct Recorder : Progress {
    int64_t total = -1, done = 0;
    int totals = 0;
    void SetTotal(int64_t t) override { total = t, ++totals; }
    void Advance(int64_t d) override {
      EXPECT_GT(d, 0);
      done += d;
    }
  } recorder;
  const std::string path = WriteTone(
      "progress.wav", [](double) { return 220.0; }, 6.0);
  PitchSummary summary;
  ASSERT_TRUE(TrackPitchFile(path, Options("cello"), &summary, recorder).ok());
  EXPECT_EQ(recorder.totals, 1);
  EXPECT_EQ(recorder.total, kPitchProgressSteps);
  EXPECT_GT(recorder.done, kPitchProgressSteps / 2);
  EXPECT_LE(recorder.done, kPitchProgressSteps);
}

TEST(TrackPitch, RowsAreExactlyAtStartPlusIOverFps) {
  testing::ToneOptions tone;
  tone.harmonics = 6;
  const auto path = WriteTone(
      "steady.wav", [](double) { return 196.0; }, 3.0, tone);
  auto o = Options("cello", 29.97);
  o.start_s = 0.25;
  const auto track = Track(path, o);
  // Rows while start + i / fps < 3 s.
  EXPECT_EQ(static_cast<int64_t>(track.frames.size()),
            static_cast<int64_t>(std::ceil((3.0 - 0.25) * 29.97)));
  for (size_t i = 0; i < track.frames.size(); ++i) {
    EXPECT_EQ(track.frames[i].frame, static_cast<int64_t>(i));
    EXPECT_DOUBLE_EQ(track.frames[i].time_s, 0.25 + i / 29.97);
  }
  ASSERT_EQ(track.hops_per_frame, 4);
  for (size_t i = 3; i + 3 < track.frames.size(); ++i) {
    ASSERT_TRUE(track.frames[i].voiced) << i;
    EXPECT_NEAR(Cents(track.frames[i].f0_hz, 196.0), 0.0, 0.5);
    EXPECT_EQ(track.frames[i].f0_hz, track.fine[i * 4].f0_hz);
  }
}

// A pitch step at a known time must switch rows at the frame nearest to it,
// whatever the step's position in a 12-minute file (no drift). The file is
// rendered in blocks and tracked in blocks: memory stays small.
TEST(TrackPitch, NoDriftOverTwelveMinutes) {
  const double period_s = 7.3;  // steps at k * 7.3 s: 220 Hz then 330 Hz
  auto f0 = [&](double t) {
    const int k = static_cast<int>(std::floor(t / period_s));
    return (k % 2 == 0) ? 220.0 : 330.0;
  };
  testing::ToneOptions tone;
  tone.harmonics = 5;
  tone.sample_rate_hz = 16000;
  const std::string path = testing::TempPath("long.wav");
  ASSERT_TRUE(testing::WriteToneWavStreaming(path, f0, 720.0, tone).ok());
  auto o = Options("cello", 30.0);
  rusage before;
  getrusage(RUSAGE_SELF, &before);
  const auto track = Track(path, o);
  rusage after;
  getrusage(RUSAGE_SELF, &after);
  // Streaming: the 12 minutes (46 MB as float at 16 kHz) are never held at once;
  // only the output rows (about 4 MB) stay.
  EXPECT_LT(after.ru_maxrss - before.ru_maxrss, 30 * 1024) << "kB of peak memory growth";
  ASSERT_EQ(track.frames.size(), 720u * 30u);
  int checked = 0;
  for (int k = 1; k * period_s < 719; ++k) {
    const double step_s = k * period_s;
    const double before = (k % 2 == 1) ? 220.0 : 330.0, after = (k % 2 == 1) ? 330.0 : 220.0;
    // Frames entirely on one side of the step (window half-width ~ 17 ms) are exact.
    const int64_t last_before = static_cast<int64_t>(std::floor((step_s - 0.04) * 30));
    const int64_t first_after = static_cast<int64_t>(std::ceil((step_s + 0.04) * 30));
    ASSERT_NEAR(Cents(track.frames[last_before].f0_hz, before), 0.0, 1.0) << step_s;
    ASSERT_NEAR(Cents(track.frames[first_after].f0_hz, after), 0.0, 1.0) << step_s;
    // And the fine track switches within one fine hop of the true time.
    int64_t switch_fine = -1;
    for (int64_t j = static_cast<int64_t>((step_s - 0.1) * track.fine_fps);
         j < static_cast<int64_t>((step_s + 0.1) * track.fine_fps);
         ++j) {
      if (std::abs(Cents(track.fine[j].f0_hz, after)) < 50) {
        switch_fine = j;
        break;
      }
    }
    ASSERT_GE(switch_fine, 0);
    EXPECT_NEAR(track.fine[switch_fine].time_s, step_s, 1.5 / track.fine_fps) << step_s;
    ++checked;
  }
  EXPECT_GT(checked, 90);
}

TEST(TrackPitch, FollowsVibratoAndGlides) {
  // 6 Hz vibrato of +-40 cents around A3, then a 1-second glide A3 -> E4.
  auto f0 = [](double t) {
    if (t < 2.0) return 220.0 * std::exp2(40.0 / 1200.0 * std::sin(2 * M_PI * 6.0 * t));
    if (t < 3.0) return 220.0 * std::exp2(7.0 / 12.0 * (t - 2.0));
    return 220.0 * std::exp2(7.0 / 12.0);
  };
  testing::ToneOptions tone;
  tone.harmonics = 8;
  const auto path = WriteTone("vibrato.wav", f0, 4.0, tone);
  const auto track = Track(path, Options("cello"));
  double worst = 0;
  for (const auto& f : track.fine) {
    if (f.time_s < 0.1 || f.time_s > 3.9) continue;
    ASSERT_TRUE(f.voiced) << f.time_s;
    worst = std::max(worst, std::abs(Cents(f.f0_hz, f0(f.time_s))));
  }
  // The window spans ~37 ms of a moving pitch; the centred estimate stays close.
  EXPECT_LT(worst, 5.0);
}

TEST(TrackPitch, SilenceAndNoiseAreUnvoiced) {
  testing::ToneOptions silent;
  silent.amplitude = 0;
  PitchSummary summary;
  const auto a = Track(WriteTone(
                           "silent.wav", [](double) { return 0.0; }, 2.0, silent),
                       Options("violin"),
                       &summary);
  EXPECT_EQ(summary.voiced_fraction, 0.0);
  ASSERT_FALSE(summary.warnings.empty());
  EXPECT_NE(summary.warnings[0].find("no voiced frames"), std::string::npos);
  testing::ToneOptions noise;
  noise.amplitude = 0;
  noise.noise = 0.1;
  Track(WriteTone(
            "noise.wav", [](double) { return 0.0; }, 2.0, noise),
        Options("cello"),
        &summary);
  EXPECT_LT(summary.voiced_fraction, 0.05);
}

TEST(TrackPitch, NotesAfterSilenceAndDeterminism) {
  auto f0 = [](double t) { return (t > 0.5 && t < 1.5) ? 440.0 : (t > 2.0 ? 110.0 : 0.0); };
  testing::ToneOptions tone;
  tone.harmonics = 6;
  const auto path = WriteTone("gaps.wav", f0, 3.0, tone);
  const auto a = Track(path, Options("cello"));
  const auto b = Track(path, Options("cello"));
  ASSERT_EQ(a.fine.size(), b.fine.size());
  for (size_t j = 0; j < a.fine.size(); ++j) {
    ASSERT_EQ(a.fine[j].f0_hz, b.fine[j].f0_hz);
    ASSERT_EQ(a.fine[j].confidence, b.fine[j].confidence);
  }
  for (const auto& f : a.frames) {
    const double truth = f0(f.time_s);
    const bool clear = std::abs(f.time_s - 0.5) > 0.05 && std::abs(f.time_s - 1.5) > 0.05 &&
                       std::abs(f.time_s - 2.0) > 0.05;
    if (!clear) continue;
    EXPECT_EQ(f.voiced, truth > 0) << f.time_s;
    if (truth > 0) {
      EXPECT_NEAR(Cents(f.f0_hz, truth), 0.0, 1.0) << f.time_s;
    }
  }
}

TEST(PitchTrackerOptions, AbsurdValuesAreErrors) {
  auto o = Options("cello");
  o.fps = 0;
  EXPECT_FALSE(o.Validate().ok());
  o.fps = -30;
  EXPECT_FALSE(o.Validate().ok());
  o.fps = 1e9;
  EXPECT_FALSE(o.Validate().ok());
  o = Options("cello");
  o.start_s = NAN;
  EXPECT_FALSE(o.Validate().ok());
  o.start_s = -1e5;
  EXPECT_FALSE(o.Validate().ok());
  o.start_s = -2.5;  // video starts before the audio: allowed
  EXPECT_TRUE(o.Validate().ok());
  o = Options("cello");
  o.range.min_f0_hz = 5000;
  EXPECT_FALSE(o.Validate().ok());
  EXPECT_FALSE(InstrumentRangeByName("kazoo").ok());
}

TEST(TrackPitch, StartPastTheEndIsAFlaggedEmptyResult) {
  const auto path = WriteTone(
      "short.wav", [](double) { return 220.0; }, 1.0);
  auto o = Options("cello");
  o.start_s = 5.0;
  PitchSummary summary;
  const auto track = Track(path, o, &summary);
  EXPECT_TRUE(track.frames.empty());
  ASSERT_FALSE(summary.warnings.empty());
  EXPECT_NE(summary.warnings[0].find("empty"), std::string::npos);
}

TEST(TrackPitch, AnySampleRateAndChannelCount) {
  for (int rate : {8000, 22050, 96000}) {
    for (int channels : {1, 6}) {
      testing::ToneOptions tone;
      tone.sample_rate_hz = rate;
      tone.harmonics = 8;
      const auto mono = testing::RenderTone([](double) { return 196.0; }, 1.0, tone);
      std::vector<float> interleaved;
      for (float v : mono) {
        for (int c = 0; c < channels; ++c) interleaved.push_back(c % 2 ? v : 0.5f * v);
      }
      const std::string path = testing::TempPath("multi.wav");
      ASSERT_TRUE(testing::WriteWav(path, interleaved, rate, channels).ok());
      PitchSummary summary;
      const auto track = Track(path, Options("viola"), &summary);
      EXPECT_EQ(summary.source_channels, channels);
      EXPECT_NEAR(summary.duration_s, 1.0, 1e-3);
      for (const auto& f : track.frames) {
        if (f.time_s < 0.1 || f.time_s > 0.9) continue;
        ASSERT_TRUE(f.voiced) << rate << " " << channels;
        EXPECT_NEAR(Cents(f.f0_hz, 196.0), 0.0, 1.0) << rate << " " << channels;
      }
    }
  }
}

TEST(TrackPitch, ZeroLengthAudioIsAFlaggedEmptyResult) {
  const std::string path = testing::TempPath("zero.wav");
  ASSERT_TRUE(testing::WriteWav(path, {}, 44100).ok());
  PitchSummary summary;
  const auto track = Track(path, Options("viola"), &summary);
  EXPECT_TRUE(track.frames.empty());
  ASSERT_FALSE(summary.warnings.empty());
  EXPECT_NE(summary.warnings[0].find("no audio samples"), std::string::npos);
}

TEST(TrackPitch, UnsupportedCodecIsOneClearError) {
  // A WAV whose format tag (0x7777) no decoder knows.
  std::string wav = "RIFF";
  auto put32 = [&](uint32_t v) {
    for (int i = 0; i < 4; ++i) wav.push_back(char(v >> (8 * i)));
  };
  auto put16 = [&](uint16_t v) {
    for (int i = 0; i < 2; ++i) wav.push_back(char(v >> (8 * i)));
  };
  put32(36 + 64);
  wav += "WAVEfmt ";
  put32(16);
  put16(0x7777);
  put16(1);
  put32(8000);
  put32(16000);
  put16(2);
  put16(16);
  wav += "data";
  put32(64);
  wav += std::string(64, '\x11');
  const std::string path = testing::TempPath("odd_codec.wav");
  ASSERT_TRUE(AtomicWriteFile(path, wav).ok());
  auto track = TrackPitchFile(path, Options("cello"), nullptr);
  ASSERT_FALSE(track.ok());
  EXPECT_EQ(track.status().message().rfind(path + ": ", 0), 0u) << track.status().message();
}

TEST(WritePitchCsv, RoundTrips) {
  std::vector<PitchFrame> frames = {{0, 0.0, 0.0, 0.1, false}, {1, 1 / 30.0, 220.125, 0.9, true}};
  const std::string path = testing::TempPath("p.csv");
  ASSERT_TRUE(WritePitchCsv(path, frames).ok());
  auto back = ReadPitchCsv(path);
  ASSERT_TRUE(back.ok());
  ASSERT_EQ(back->size(), 2u);
  EXPECT_EQ((*back)[1].frame, 1);
  EXPECT_NEAR((*back)[1].f0_hz, 220.125, 1e-4);
  EXPECT_TRUE((*back)[1].voiced);
  EXPECT_FALSE((*back)[0].voiced);
}

// `arco run` hands its pitch to the refinement as ParsePitchCsv(FormatPitchCsv(...)):
// exactly what ReadPitchCsv gives for the file WritePitchCsv writes, value for value.
TEST(ParsePitchCsv, OfFormatPitchCsvIsWhatTheFileReadsBackAs) {
  std::vector<PitchFrame> frames;
  for (int i = 0; i < 50; ++i) {
    frames.push_back({i, 0.1 + i / 29.97, 100.0 + i * 3.14159265, 0.01 * i + 1e-5, i % 3 != 0});
  }
  const std::string path = testing::TempPath("p.csv");
  ASSERT_TRUE(WritePitchCsv(path, frames).ok());
  EXPECT_EQ(*ReadFileToString(path), FormatPitchCsv(frames));
  auto file = ReadPitchCsv(path);
  auto memory = ParsePitchCsv(FormatPitchCsv(frames), path);
  ASSERT_TRUE(file.ok() && memory.ok());
  ASSERT_EQ(file->size(), memory->size());
  for (size_t i = 0; i < file->size(); ++i) {
    EXPECT_EQ((*file)[i].time_s, (*memory)[i].time_s);
    EXPECT_EQ((*file)[i].f0_hz, (*memory)[i].f0_hz);
    EXPECT_EQ((*file)[i].confidence, (*memory)[i].confidence);
    EXPECT_EQ((*file)[i].voiced, (*memory)[i].voiced);
  }
}

TEST(ReadPitchCsv, MalformedRowsNameTheFileAndLine) {
  const std::string path = testing::TempPath("bad_pitch.csv");
  const std::string header = "frame,time_s,f0_hz,confidence,voiced\n";
  for (const char* row : {"0,0.0,220\n",
                          "0,0.0,220,0.9,1,7\n",
                          "0,0.0,220,0.9,2\n",
                          "0,,220,0.9,1\n",
                          "0,0.0,220x,0.9,1\n"}) {
    ASSERT_TRUE(AtomicWriteFile(path, header + "0,0.0,220,0.9,1\n" + row).ok());
    const auto r = ReadPitchCsv(path);
    ASSERT_FALSE(r.ok()) << row;
    EXPECT_EQ(r.status().message().rfind(path + ":3: ", 0), 0u) << r.status().message();
  }
}

}  // namespace
}  // namespace arco::audio

namespace arco::audio {
namespace {

const std::string kSpd = std::string(ARCO_SHARED_DATA_DIR) + "/spd/";

// background.wav opens with C2 D2 E2 F2 G2 on the C and G strings (0.5-4.7 s):
// every voiced frame there must be one of those notes, in that octave.
TEST(TrackPitchRealCello, LowScaleNotesInTheRightOctave) {
  auto track = TrackPitchFile(kSpd + "background.wav", Options("cello"), nullptr);
  ASSERT_TRUE(track.ok()) << track.status().message();
  const double notes[] = {65.41, 73.42, 82.41, 87.31, 98.00};  // C2 D2 E2 F2 G2
  int voiced = 0, on_scale = 0, total = 0;
  int seen[5] = {0, 0, 0, 0, 0};
  int last_note = 0;
  bool in_order = true;
  for (const auto& f : track->frames) {
    if (f.time_s < 0.5 || f.time_s > 4.7) continue;
    ++total;
    if (!f.voiced) continue;
    ++voiced;
    for (int n = 0; n < 5; ++n) {
      if (std::abs(Cents(f.f0_hz, notes[n])) < 60) {
        ++on_scale;
        ++seen[n];
        if (n < last_note) in_order = false;
        last_note = n;
      }
    }
  }
  EXPECT_GT(voiced, 0.8 * total);
  EXPECT_GE(on_scale, voiced - 2) << "frames off the C2-G2 notes (octave errors?)";
  for (int n = 0; n < 5; ++n) EXPECT_GE(seen[n], 5) << "note " << n << " missing";
  EXPECT_TRUE(in_order);
}

// CREPE (a peer, with octave errors of its own) where its confidence >= 0.8:
// agree within 50 cents on most frames, and modulo one octave on nearly all.
// In the low register (< 4.7 s) we must never be an octave above CREPE.
TEST(TrackPitchRealCello, AgreesWithCrepeUpToItsOctaveErrors) {
  auto o = Options("cello", 100.0);  // 10 ms rows, like the CREPE file
  o.hops_per_frame = 1;
  auto track = TrackPitchFile(kSpd + "background.wav", o, nullptr);
  ASSERT_TRUE(track.ok());
  std::ifstream in(kSpd + "background_crepe_pitch.csv");
  ASSERT_TRUE(in.good());
  std::string line;
  int n = 0, within = 0, modulo_octave = 0, above_low = 0;
  while (std::getline(in, line)) {
    double t, f, c;
    if (std::sscanf(line.c_str(), "%lf,%lf,%lf", &t, &f, &c) != 3 || c < 0.8) continue;
    const int64_t i = std::llround(t * 100.0);
    if (i >= static_cast<int64_t>(track->frames.size())) continue;
    const auto& ours = track->frames[i];
    ++n;
    if (!ours.voiced) continue;
    const double d = Cents(ours.f0_hz, f);
    if (std::abs(d) < 50) ++within;
    if (std::abs(d) < 50 || std::abs(std::abs(d) - 1200) < 50) ++modulo_octave;
    if (t < 4.7 && std::abs(d - 1200) < 100) ++above_low;
  }
  ASSERT_GT(n, 1000);
  EXPECT_GT(within, 0.93 * n);
  EXPECT_GT(modulo_octave, 0.99 * n);
  EXPECT_EQ(above_low, 0);
}

}  // namespace
}  // namespace arco::audio

namespace arco::audio {
namespace {

// Stopping at max_frames reads less than the file holds: that is not truncation.
TEST(TrackPitch, MaxFramesDoesNotWarnOfTruncation) {
  PitchTrackerOptions o;
  o.range = *InstrumentRangeByName("cello");
  o.fps = 30;
  o.max_frames = 30;  // 1 s of a 20 s file
  PitchSummary summary;
  auto track =
      TrackPitchFile(std::string(ARCO_SHARED_DATA_DIR) + "/spd/background.wav", o, &summary);
  ASSERT_TRUE(track.ok()) << track.status().message();
  EXPECT_EQ(track->frames.size(), 30u);
  for (const auto& w : summary.warnings) EXPECT_EQ(w.find("truncated"), std::string::npos) << w;
}

}  // namespace
}  // namespace arco::audio
