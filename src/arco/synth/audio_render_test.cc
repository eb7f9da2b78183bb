// Rendered audio against the truth pitch, tracked by arco's own tracker.
#include "arco/synth/audio_render.h"

#include <unistd.h>

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "arco/audio/pitch_tracker.h"
#include "arco/synth/test_instruments.h"

namespace arco::synth {
namespace {

// A temporary folder of this test process only: ctest runs the tests of one binary
// as separate processes, possibly at the same time.
inline std::string PerProcessTempDir() {
  static const std::string dir = [] {
    const std::string d = ::testing::TempDir() + "/arco-" + std::to_string(::getpid());
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

struct Case {
  const char* instrument;
  const char* piece;
  int program;
};

class RenderedAudio : public ::testing::TestWithParam<Case> {};

TEST_P(RenderedAudio, TrackedPitchMatchesTruthWithinFiveCents) {
  const Case c = GetParam();
  ScoreInstrument ins = std::string(c.instrument) == "cello" ? testing::Cello() : testing::Violin();
  auto score = MakeBuiltInPiece(c.piece, ins);
  ASSERT_TRUE(score.ok());
  const Score s = TruncateScore(*score, 6.0);
  auto plan = PlanFingering(s, ins);
  ASSERT_TRUE(plan.ok());
  auto perf = MakePerformance(s, *plan, {}, 5);
  ASSERT_TRUE(perf.ok());
  const std::string dir = PerProcessTempDir() + "/render_" + c.instrument;
  std::filesystem::create_directories(dir);
  AudioRenderSummary summary;
  const Status st = RenderPerformanceAudio(
      *perf, c.program, c.instrument, {}, dir, dir + "/p.mid", dir + "/p.wav", 0, &summary);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_FALSE(summary.key_offset_cents.empty());
  audio::PitchTrackerOptions po;
  po.range = *audio::InstrumentRangeByName(c.instrument);
  po.fps = 100;
  audio::PitchSummary ps;
  auto track = audio::TrackPitchFile(dir + "/p.wav", po, &ps);
  ASSERT_TRUE(track.ok()) << track.status().message();
  std::vector<double> err;
  int unvoiced = 0;
  for (const audio::PitchFrame& f : track->frames) {
    const int i = perf->NoteIndexAt(f.time_s);
    if (i < 0) continue;
    const auto& n = perf->notes[static_cast<size_t>(i)].note;
    // Scored like the audio layer's render tests: the sample needs ~60 ms to speak.
    if (f.time_s < n.onset_s + 0.06 || f.time_s > n.offset_s - 0.03) continue;
    if (!f.voiced) {
      ++unvoiced;
      continue;
    }
    err.push_back(std::abs(1200 * std::log2(f.f0_hz / perf->F0HzAt(f.time_s))));
    if (getenv("ARCO_DEBUG_AUDIO")) {
      std::printf("%d t=%.2f key %d err %.1f vib %.1f off %.1f\n",
                  i,
                  f.time_s,
                  n.midi_note,
                  1200 * std::log2(f.f0_hz / perf->F0HzAt(f.time_s)),
                  perf->notes[static_cast<size_t>(i)].VibratoCentsOnlyAt(f.time_s),
                  summary.key_offset_cents[n.midi_note]);
    }
  }
  ASSERT_GT(err.size(), 200u);
  std::sort(err.begin(), err.end());
  const double median = err[err.size() / 2];
  const double p90 = err[err.size() * 9 / 10];
  std::printf("%s %s: median %.2f cents, p90 %.2f cents, unvoiced %d of %zu\n",
              c.instrument,
              c.piece,
              median,
              p90,
              unvoiced,
              err.size() + unvoiced);
  EXPECT_LT(median, 5.0);
  EXPECT_LT(p90, 5.0);
  EXPECT_LT(unvoiced, static_cast<int>(err.size()) / 20);
}

INSTANTIATE_TEST_SUITE_P(Pieces,
                         RenderedAudio,
                         ::testing::Values(Case{"cello", "slow-melody", 42},
                                           Case{"violin", "scale-2oct", 40}));

TEST(PerformanceToMidi, BendsCarryIntonationAndVibratoMinusKeyOffset) {
  auto score = MakeBuiltInPiece("slow-melody", testing::Cello());
  auto plan = PlanFingering(*score, testing::Cello());
  auto perf = MakePerformance(*score, *plan, {}, 2);
  ASSERT_TRUE(perf.ok());
  const int key = perf->notes[0].note.midi_note;
  AudioRenderOptions o;
  o.latency_s = 0;
  SampleContour c;
  c.cents = {7.0, 7.0};
  const audio::MidiFile f = PerformanceToMidi(*perf, 42, {{key, c}}, o);
  ASSERT_EQ(f.tracks.size(), 1u);
  EXPECT_EQ(f.tracks[0].program, 42);
  EXPECT_EQ(f.tracks[0].notes.size(), perf->notes.size());
  const auto& b = f.tracks[0].bends.front();
  EXPECT_NEAR(b.time_s, perf->notes[0].note.onset_s, 1e-12);
  EXPECT_NEAR(b.semitones, (perf->notes[0].CentsAt(b.time_s) - 7.0) / 100, 1e-12);
  AudioRenderOptions bad;
  bad.bend_step_s = 0;
  EXPECT_FALSE(bad.Validate().ok());
}

}  // namespace
}  // namespace arco::synth
