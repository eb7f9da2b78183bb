// Rendered audio against the truth pitch, measured two ways: with arco's own
// tracker, and with the harmonic-peak fit that tuned the soundfont (an
// independent offline measurement, so the audio's truth is not arco's opinion).
#include "arco/synth/audio_render.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "arco/audio/audio_reader.h"
#include "arco/audio/harmonic_fit.h"
#include "arco/audio/pitch_tracker.h"
#include "arco/synth/test_instruments.h"
#include "arco/testing/temp_dir.h"

namespace arco::synth {
namespace {

using arco::testing::PerProcessTempDir;

struct Case {
  const char* instrument;
  const char* piece;
  int program;
};

class RenderedAudio : public ::testing::TestWithParam<Case> {};

TEST_P(RenderedAudio, TrackedAndFittedPitchMatchTruth) {
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
      *perf, c.program, {}, dir, dir + "/p.mid", dir + "/p.wav", 0, &summary);
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

  // The same audio by the harmonic-peak fit, every 10 ms inside each note, against
  // the truth averaged (in cents) over the fit's window: a long window averages
  // the vibrato, so the window mean is what it measures.
  auto reader = audio::OpenAudio(dir + "/p.wav");
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  const int rate = (*reader)->info().sample_rate_hz;
  std::vector<float> samples, block(1 << 15);
  while (true) {
    auto got = (*reader)->ReadMono(block.data(), 1 << 15);
    ASSERT_TRUE(got.ok());
    if (*got == 0) break;
    samples.insert(samples.end(), block.begin(), block.begin() + *got);
  }
  std::vector<double> fit_err;
  for (const PerformedNote& pn : perf->notes) {
    const double nominal_hz = perf->a4_hz * std::exp2((pn.note.midi_note - 69) / 12.0);
    const int window = audio::HarmonicFitWindow(rate, nominal_hz);
    const double half_s = 0.5 * window / rate;
    audio::HarmonicPeakFit fit(rate, window);
    for (double t = pn.note.onset_s + 0.06 + half_s; t < pn.note.offset_s - 0.03 - half_s;
         t += 0.01) {
      const int64_t start = std::llround(t * rate) - window / 2;
      if (start < 0 || start + window > static_cast<int64_t>(samples.size())) continue;
      const double f0 = fit.F0Hz(samples.data() + start, window, nominal_hz);
      if (!std::isfinite(f0)) continue;
      double truth_cents = 0;
      for (int j = 0; j < 16; ++j) {
        const double tj = t - half_s + (j + 0.5) * 2 * half_s / 16;
        truth_cents += 1200 * std::log2(perf->F0HzAt(tj) / nominal_hz) / 16;
      }
      fit_err.push_back(std::abs(1200 * std::log2(f0 / nominal_hz) - truth_cents));
    }
  }
  ASSERT_GT(fit_err.size(), 200u);
  std::sort(fit_err.begin(), fit_err.end());
  const double fit_median = fit_err[fit_err.size() / 2];
  const double fit_p90 = fit_err[fit_err.size() * 9 / 10];
  std::printf("%s %s: harmonic fit median %.2f cents, p90 %.2f cents over %zu windows\n",
              c.instrument,
              c.piece,
              fit_median,
              fit_p90,
              fit_err.size());
  EXPECT_LT(fit_median, 3.0);
  EXPECT_LT(fit_p90, 5.0);
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

TEST(PerformanceToMidi, DoubleStopsUpperNotesGoOnASecondChannel) {
  auto score = MakeBuiltInPiece("double-stops", testing::Violin());
  auto plan = PlanFingering(*score, testing::Violin());
  auto perf = MakePerformance(*score, *plan, {}, 2);
  ASSERT_TRUE(perf.ok());
  AudioRenderOptions o;
  o.latency_s = 0;
  const audio::MidiFile f = PerformanceToMidi(*perf, 40, {}, o);
  ASSERT_EQ(f.tracks.size(), 2u);
  EXPECT_EQ(f.tracks[0].notes.size(), perf->notes.size());
  EXPECT_EQ(f.tracks[1].channel, 1);
  EXPECT_EQ(f.tracks[1].program, 40);
  ASSERT_EQ(f.tracks[1].notes.size(), 12u);  // 4 intervals on 3 string pairs
  size_t k = 0;
  for (const PerformedNote& n : perf->notes) {
    if (!n.note.IsDoubleStop()) continue;
    EXPECT_EQ(f.tracks[1].notes[k].midi_note, n.note.second_midi_note);
    EXPECT_NEAR(f.tracks[1].notes[k].onset_s, n.note.onset_s, 1e-12);
    ++k;
  }
  // A single-note piece keeps one track.
  auto single = MakeBuiltInPiece("scale-2oct", testing::Violin());
  auto single_plan = PlanFingering(*single, testing::Violin());
  auto single_perf = MakePerformance(*single, *single_plan, {}, 2);
  EXPECT_EQ(PerformanceToMidi(*single_perf, 40, {}, o).tracks.size(), 1u);
}

}  // namespace
}  // namespace arco::synth
