#include "arco/synth/score.h"

#include <gtest/gtest.h>

#include "arco/synth/test_instruments.h"

namespace arco::synth {
namespace {

using testing::Bass;
using testing::Cello;
using testing::Viola;
using testing::Violin;

TEST(MidiNoteName, NamesOctavesAndSharps) {
  EXPECT_EQ(MidiNoteName(60), "C4");
  EXPECT_EQ(MidiNoteName(36), "C2");
  EXPECT_EQ(MidiNoteName(30), "F#1");
  EXPECT_EQ(MidiNoteName(69), "A4");
  EXPECT_EQ(MidiNoteName(0), "C-1");
  EXPECT_NEAR(MidiToHz(69), 440.0, 1e-12);
  EXPECT_NEAR(MidiToHz(36), 65.406, 1e-3);
  EXPECT_NEAR(MidiToHz(57, 442.0), 221.0, 1e-9);
}

TEST(MakeBuiltInPiece, EveryPieceIsValidOnEveryInstrument) {
  for (const auto& ins : {Cello(), Violin(), Viola(), Bass()}) {
    for (const auto& name : BuiltInPieceNames()) {
      auto score = MakeBuiltInPiece(name, ins);
      ASSERT_TRUE(score.ok()) << ins.name << " " << name << ": " << score.status().message();
      EXPECT_GT(score->notes.size(), 10u);
      EXPECT_TRUE(ValidateScore(*score, ins, name).ok());
      EXPECT_GT(score->duration_s, score->notes.back().offset_s);
      EXPECT_FALSE(DescribeBuiltInPiece(name).empty());
    }
  }
}

TEST(MakeBuiltInPiece, DoubleStopsPlayFourIntervalsOnEveryStringPairAfterTheirUpperNote) {
  for (const auto& ins : {Cello(), Violin(), Viola(), Bass()}) {
    auto score = MakeBuiltInPiece("double-stops", ins);
    ASSERT_TRUE(score.ok()) << score.status().message();
    std::vector<int> intervals;
    for (size_t i = 0; i < score->notes.size(); ++i) {
      const ScoreNote& n = score->notes[i];
      if (!n.IsDoubleStop()) continue;
      intervals.push_back(n.second_midi_note - n.midi_note);
      ASSERT_GT(i, 0u);
      EXPECT_FALSE(score->notes[i - 1].IsDoubleStop());
      EXPECT_EQ(score->notes[i - 1].midi_note, n.second_midi_note) << ins.name;
    }
    const std::vector<int> one_pair = {9, 4, 7, 12};
    ASSERT_EQ(intervals.size(), 4 * (ins.open_string_midi.size() - 1)) << ins.name;
    for (size_t k = 0; k < intervals.size(); ++k) EXPECT_EQ(intervals[k], one_pair[k % 4]);
  }
}

// Each chord: its top note alone, then its lower pair briefly and its upper pair held, the
// pairs on adjacent strings from the same stops (a 3-note chord's pairs share the middle
// note); shapes wider than the hand are left out (the double bass's 4-note A major).
TEST(MakeBuiltInPiece, ChordsRollTwoPairsAfterTheirTopNote) {
  for (const auto& ins : {Cello(), Violin(), Viola(), Bass()}) {
    auto score = MakeBuiltInPiece("chords", ins);
    ASSERT_TRUE(score.ok()) << score.status().message();
    std::vector<std::vector<int>> chords;
    for (size_t i = 0; i < score->notes.size(); ++i) {
      const ScoreNote& upper = score->notes[i];
      if (!upper.chord_upper_pair) continue;
      ASSERT_GE(i, 2u);
      const ScoreNote& lower = score->notes[i - 1];
      const ScoreNote& top = score->notes[i - 2];
      ASSERT_TRUE(lower.IsDoubleStop() && upper.IsDoubleStop());
      EXPECT_FALSE(lower.chord_upper_pair);
      EXPECT_FALSE(top.IsDoubleStop());
      EXPECT_EQ(top.midi_note, upper.second_midi_note);
      EXPECT_LT(lower.offset_s - lower.onset_s, 0.5 * (upper.offset_s - upper.onset_s));
      EXPECT_LT(upper.onset_s - lower.offset_s, 0.05);  // rolled: no rest between the pairs
      std::vector<int> chord = {lower.midi_note, lower.second_midi_note};
      if (upper.midi_note != lower.second_midi_note) chord.push_back(upper.midi_note);
      chord.push_back(upper.second_midi_note);
      chords.push_back(chord);
    }
    const bool bass = ins.name == "double_bass";
    ASSERT_EQ(chords.size(), bass ? 4u : 5u) << ins.name;
    // The first chord: all four open strings' lowest octave shape, stops 0, 0, 2, 3.
    const auto& open = ins.open_string_midi;
    EXPECT_EQ(chords[0], (std::vector<int>{open[0], open[1], open[2] + 2, open[3] + 3}));
    EXPECT_EQ(chords[1].size(), 3u);
    if (ins.name == "violin") {
      EXPECT_EQ(chords[0], (std::vector<int>{55, 62, 71, 79}));  // G major G3 D4 B4 G5
      EXPECT_EQ(chords[3], (std::vector<int>{57, 64, 73, 81}));  // A major A3 E4 C#5 A5
    }
    if (ins.name == "cello") {
      EXPECT_EQ(chords[0], (std::vector<int>{36, 43, 52, 60}));  // C major C2 G2 E3 C4
      EXPECT_EQ(chords[2], (std::vector<int>{38, 45, 54}));      // D major D2 A2 F#3
    }
  }
}

TEST(ValidateScore, RejectsAChordUpperPairWithoutItsLowerPair) {
  Score s;
  s.notes.push_back({55, 0.1, 0.4, 80});
  s.notes.push_back({62, 0.4, 1.0, 80, 71});
  s.notes.back().chord_upper_pair = true;
  s.duration_s = 1.5;
  const Status status = ValidateScore(s, Violin(), "take");
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("take: the chord's upper pair at 0.400 s"), std::string::npos)
      << status.message();
  s.notes[0].second_midi_note = 62;  // G3 + D4, then D4 + B4: a 3-note chord
  EXPECT_TRUE(ValidateScore(s, Violin(), "take").ok());
  s.notes[1].midi_note = 60;  // C4 + B4 under the lower pair's D4
  EXPECT_FALSE(ValidateScore(s, Violin(), "take").ok());
}

TEST(ValidateScore, RejectsADoubleStopWhoseSecondNoteIsNotAbove) {
  Score s;
  s.notes.push_back({60, 0.1, 0.5, 80, 55});
  s.duration_s = 1;
  const Status status = ValidateScore(s, Violin(), "take.mid");
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("take.mid: double stop C4+G3 at 0.100 s"), std::string::npos)
      << status.message();
  s.notes[0].second_midi_note = 67;
  EXPECT_TRUE(ValidateScore(s, Violin(), "take.mid").ok());
}

TEST(MakeBuiltInPiece, ScaleStartsOnLowestOpenStringAndClimbsTwoOctaves) {
  auto score = MakeBuiltInPiece("scale-2oct", Cello());
  ASSERT_TRUE(score.ok());
  ASSERT_EQ(score->notes.size(), 29u);
  EXPECT_EQ(score->notes.front().midi_note, 36);  // C2
  EXPECT_EQ(score->notes[1].midi_note, 38);       // D2
  EXPECT_EQ(score->notes[14].midi_note, 60);      // C4
  EXPECT_EQ(score->notes.back().midi_note, 36);
  // Tempo scale stretches every time.
  auto slow = MakeBuiltInPiece("scale-2oct", Cello(), 2.0);
  ASSERT_TRUE(slow.ok());
  EXPECT_NEAR(slow->notes[3].onset_s - 0.25, 2 * (score->notes[3].onset_s - 0.25), 1e-12);
}

TEST(MakeBuiltInPiece, SlowMelodyHasLongNotes) {
  auto score = MakeBuiltInPiece("slow-melody", Cello());
  ASSERT_TRUE(score.ok());
  int long_notes = 0;
  for (const auto& n : score->notes) long_notes += (n.offset_s - n.onset_s) > 1.0;
  EXPECT_GE(long_notes, 5);
}

TEST(MakeBuiltInPiece, UnknownPieceListsTheNames) {
  auto score = MakeBuiltInPiece("bolero", Cello());
  ASSERT_FALSE(score.ok());
  EXPECT_NE(score.status().message().find("unknown piece 'bolero'"), std::string::npos);
  EXPECT_NE(score.status().message().find("scale-2oct"), std::string::npos);
  EXPECT_FALSE(MakeBuiltInPiece("scale-2oct", Cello(), 0.0).ok());
}

TEST(ValidateScore, NamesTheOutOfRangeNote) {
  Score s;
  s.notes = {{48, 0.0, 0.5, 80}, {30, 2.5, 3.0, 80}};
  const Status status = ValidateScore(s, Cello(), "tune.mid");
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message(),
            "tune.mid: note 30 (F#1) at 2.500 s is outside the cello's range C2 (36) to A5 (81)");
  s.notes = {{48, 0.0, 0.5, 80}, {50, 0.4, 0.8, 80}};
  EXPECT_NE(ValidateScore(s, Cello(), "x").message().find("starts before"), std::string::npos);
  s.notes = {{48, 0.5, 0.5, 80}};
  EXPECT_NE(ValidateScore(s, Cello(), "x").message().find("no positive duration"),
            std::string::npos);
  s.notes.clear();
  EXPECT_FALSE(ValidateScore(s, Cello(), "x").ok());
}

TEST(TruncateScore, KeepsNotesBeforeTheLimit) {
  auto score = MakeBuiltInPiece("scale-2oct", Cello());
  ASSERT_TRUE(score.ok());
  const Score t = TruncateScore(*score, 3.0);
  ASSERT_FALSE(t.notes.empty());
  EXPECT_LT(t.notes.size(), score->notes.size());
  EXPECT_LE(t.notes.back().offset_s, 3.0);
  EXPECT_LE(t.duration_s, 3.5);
  EXPECT_EQ(TruncateScore(*score, 0).notes.size(), score->notes.size());
}

}  // namespace
}  // namespace arco::synth
