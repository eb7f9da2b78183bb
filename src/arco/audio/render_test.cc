// Music rendered at test time by fluidsynth from MIDI this test writes (real
// sampled cello, violin, viola and contrabass, GM programs 42/40/41/43), with
// pitch-bend vibrato and glides: truth f0 at every frame is known.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "arco/audio/notes.h"
#include "arco/audio/pitch_tracker.h"
#include "arco/audio/test_music.h"
#include "arco/audio/test_signals.h"

namespace arco::audio {
namespace {

struct Score {
  int voiced = 0, unvoiced = 0, hit50 = 0, hit25 = 0, recalled = 0, false_alarms = 0;
  double rpa50() const { return voiced ? double(hit50) / voiced : 0; }
  double rpa25() const { return voiced ? double(hit25) / voiced : 0; }
  double recall() const { return voiced ? double(recalled) / voiced : 0; }
  double false_alarm() const { return unvoiced ? double(false_alarms) / unvoiced : 0; }
};

Score Evaluate(const testing::TestMusic& music, const std::vector<PitchFrame>& frames) {
  Score s;
  for (const auto& f : frames) {
    const auto v = music.Voicing(f.time_s);
    if (v == testing::TruthVoicing::kUnvoiced) {
      ++s.unvoiced;
      s.false_alarms += f.voiced;
    } else if (v == testing::TruthVoicing::kVoiced) {
      ++s.voiced;
      s.recalled += f.voiced;
      if (!f.voiced) continue;
      const double cents = std::abs(1200.0 * std::log2(f.f0_hz / music.F0Hz(f.time_s)));
      s.hit50 += cents <= 50;
      s.hit25 += cents <= 25;
    }
  }
  return s;
}

class RenderedInstrument : public ::testing::TestWithParam<const char*> {};

TEST_P(RenderedInstrument, TracksTruthWithinCents) {
  const std::string instrument = GetParam();
  auto music = testing::MakeTestMusic(instrument, 24, 7);
  const std::string midi = testing::TempPath(instrument + ".mid");
  const std::string wav = testing::TempPath(instrument + ".wav");
  ASSERT_TRUE(WriteMidiFile(midi, music.midi).ok());
  ASSERT_TRUE(testing::RenderWithFluidsynth(midi, wav).ok());
  ASSERT_TRUE(testing::MarkSilentNotes(wav, &music).ok());
  PitchTrackerOptions options;
  options.range = *InstrumentRangeByName(instrument);
  options.fps = 30;
  PitchSummary summary;
  auto track = TrackPitchFile(wav, options, &summary);
  ASSERT_TRUE(track.ok()) << track.status().message();
  const Score s = Evaluate(music, track->fine);
  std::printf("%s: RPA50 %.4f RPA25 %.4f recall %.4f false alarms %.4f (%d voiced, %d unvoiced)\n",
              instrument.c_str(),
              s.rpa50(),
              s.rpa25(),
              s.recall(),
              s.false_alarm(),
              s.voiced,
              s.unvoiced);
  ASSERT_GT(s.voiced, 1000);
  ASSERT_GT(s.unvoiced, 100);
  EXPECT_GE(s.rpa50(), 0.98);
  // 25 cents: the sampled violin and viola carry their own vibrato (+-30 cents
  // on high notes), so this bound is looser than the tracker itself.
  EXPECT_GE(s.rpa25(), 0.90);
  EXPECT_GE(s.recall(), 0.98);
  EXPECT_LE(s.false_alarm(), 0.02);
  // Notes: one detected note per MIDI note (+-20%), most with the right MIDI number.
  const auto notes = SegmentNotes(track->fine, track->fine_fps, NoteOptions());
  const auto& truth = music.midi.tracks[0].notes;
  int matched = 0;
  for (const auto& n : truth) {
    for (const auto& d : notes.notes) {
      const double mid = 0.5 * (d.onset_s + d.offset_s);
      if (mid > n.onset_s && mid < n.offset_s && d.midi_note == n.midi_note) {
        ++matched;
        break;
      }
    }
  }
  std::printf("%s: %zu notes detected, %d of %zu MIDI notes matched\n",
              instrument.c_str(),
              notes.notes.size(),
              matched,
              truth.size());
  EXPECT_GE(matched, static_cast<int>(0.9 * truth.size()));
}

// Each key's own sound (the reference of bench/pitch_peers.sh's second table):
// measured nearly everywhere it is scored (from 60 ms after the onset; the
// attack before that is not), and within a semitone of the key.
TEST_P(RenderedInstrument, KeyContoursAreMeasured) {
  const std::string instrument = GetParam();
  auto music = testing::MakeTestMusic(instrument, 24, 7);
  ASSERT_TRUE(testing::MeasureKeyContours(testing::TempPath(""), &music).ok());
  ASSERT_FALSE(music.key_contours.empty());
  for (const auto& [key, contour] : music.key_contours) {
    int finite = 0, scored = 0;
    for (size_t i = 0; i < contour.cents.size(); ++i) {
      if (i * contour.step_s < 0.06) continue;
      ++scored;
      const double c = contour.cents[i];
      if (!std::isfinite(c)) continue;
      ++finite;
      EXPECT_LT(std::abs(c), 100.0) << instrument << " key " << key;
    }
    EXPECT_GE(finite, 0.9 * scored) << instrument << " key " << key;
  }
}

INSTANTIATE_TEST_SUITE_P(FluidR3,
                         RenderedInstrument,
                         ::testing::Values("cello", "violin", "viola", "bass"));

}  // namespace
}  // namespace arco::audio
