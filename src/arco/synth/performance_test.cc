#include "arco/synth/performance.h"

#include <gtest/gtest.h>

#include <cmath>

#include "arco/synth/test_instruments.h"

namespace arco::synth {
namespace {

Performance Make(const std::string& piece, uint64_t seed, ExpressionOptions o = {}) {
  auto score = MakeBuiltInPiece(piece, testing::Cello());
  EXPECT_TRUE(score.ok());
  auto plan = PlanFingering(*score, testing::Cello());
  EXPECT_TRUE(plan.ok());
  auto perf = MakePerformance(*score, *plan, o, seed);
  EXPECT_TRUE(perf.ok());
  return *perf;
}

TEST(MakePerformance, IntonationWithinLimitsAndOpenStringsInTune) {
  const Performance p = Make("open-strings", 3);
  int open = 0;
  for (const auto& n : p.notes) {
    EXPECT_LE(std::abs(n.intonation_cents), 15.0);
    if (n.fingering.finger == 0) {
      ++open;
      EXPECT_EQ(n.intonation_cents, 0.0);
      EXPECT_EQ(n.vibrato_rate_hz, 0.0);
    }
  }
  EXPECT_GT(open, 0);
}

TEST(MakePerformance, LongNotesVibrateWithinTheDrawnExtent) {
  const Performance p = Make("slow-melody", 1);
  int vibrato_notes = 0;
  for (const auto& n : p.notes) {
    if (n.vibrato_rate_hz <= 0) continue;
    ++vibrato_notes;
    EXPECT_GE(n.vibrato_rate_hz, 5.0);
    EXPECT_LE(n.vibrato_rate_hz, 6.5);
    double max_dev = 0;
    for (double t = n.note.onset_s; t < n.note.offset_s; t += 0.001) {
      max_dev = std::max(max_dev, std::abs(n.CentsAt(t) - n.intonation_cents));
    }
    EXPECT_LE(max_dev, n.vibrato_extent_cents + 1e-9);
    if (n.note.offset_s - n.note.onset_s > 1.0) {
      EXPECT_GT(max_dev, 0.9 * n.vibrato_extent_cents);
    }
    // Straight tone at the onset.
    EXPECT_EQ(n.CentsAt(n.note.onset_s), n.intonation_cents);
  }
  EXPECT_GE(vibrato_notes, 10);
}

TEST(MakePerformance, PitchQueriesFollowTheNotes) {
  const Performance p = Make("scale-2oct", 0);
  const PerformedNote& n = p.notes[4];
  const double t = n.note.onset_s + 0.05;
  EXPECT_EQ(p.NoteIndexAt(t), 4);
  EXPECT_NEAR(p.MidiPitchAt(t), n.note.midi_note + n.CentsAt(t) / 100, 1e-12);
  EXPECT_NEAR(p.F0HzAt(t), 440 * std::pow(2.0, (p.MidiPitchAt(t) - 69) / 12), 1e-9);
  EXPECT_EQ(p.NoteIndexAt(0.0), -1);
  EXPECT_EQ(p.F0HzAt(0.0), 0.0);
  EXPECT_EQ(p.NoteIndexAt(n.note.offset_s + 1e-6), -1);  // articulation gap
}

TEST(MakePerformance, DeterministicPerSeed) {
  const Performance a = Make("slow-melody", 7), b = Make("slow-melody", 7),
                    c = Make("slow-melody", 8);
  ASSERT_EQ(a.notes.size(), b.notes.size());
  bool differs = false;
  for (size_t i = 0; i < a.notes.size(); ++i) {
    EXPECT_EQ(a.notes[i].intonation_cents, b.notes[i].intonation_cents);
    EXPECT_EQ(a.notes[i].vibrato_rate_hz, b.notes[i].vibrato_rate_hz);
    differs |= a.notes[i].intonation_cents != c.notes[i].intonation_cents;
  }
  EXPECT_TRUE(differs);
}

TEST(MakePerformance, DoubleStopsSoundBothNotesWithOneVibrato) {
  const Performance p = Make("double-stops", 4);
  int doubles = 0;
  for (const PerformedNote& n : p.notes) {
    const double t = n.note.onset_s + 0.6 * (n.note.offset_s - n.note.onset_s);
    if (!n.note.IsDoubleStop()) {
      EXPECT_EQ(p.SecondF0HzAt(t), 0.0);
      continue;
    }
    ++doubles;
    EXPECT_LE(std::abs(n.second_intonation_cents), 15.0);
    const double cents2 = 1200 * std::log2(p.SecondF0HzAt(t) / MidiToHz(n.note.second_midi_note));
    EXPECT_NEAR(cents2, n.SecondCentsAt(t), 1e-9);
    if (n.fingering.second_finger == 0) {
      EXPECT_EQ(n.SecondCentsAt(t), 0.0);  // an open string sounds in tune
    } else {
      EXPECT_NEAR(n.SecondCentsAt(t) - n.second_intonation_cents,
                  n.CentsAt(t) - n.intonation_cents,
                  1e-12);  // the same vibrato on both fingers
    }
  }
  EXPECT_EQ(doubles, 12);
  EXPECT_EQ(p.SecondF0HzAt(p.notes.back().note.offset_s + 0.1), 0.0);
}

TEST(ExpressionOptions, RejectsBadValues) {
  ExpressionOptions o;
  o.max_intonation_cents = 80;
  EXPECT_FALSE(o.Validate().ok());
  o = {};
  o.vibrato_rate_max_hz = 1;
  EXPECT_FALSE(o.Validate().ok());
  o = {};
  o.a4_hz = 0;
  EXPECT_FALSE(o.Validate().ok());
  EXPECT_TRUE(ExpressionOptions{}.Validate().ok());
}

}  // namespace
}  // namespace arco::synth
