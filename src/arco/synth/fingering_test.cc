#include "arco/synth/fingering.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdlib>

#include "arco/synth/test_instruments.h"

namespace arco::synth {
namespace {

using testing::Cello;
using testing::Violin;

Score Notes(std::vector<std::pair<int, double>> notes) {
  Score s;
  double t = 0;
  for (auto [m, d] : notes) {
    s.notes.push_back({m, t, t + d - 0.02, 80});
    t += d;
  }
  s.duration_s = t + 0.5;
  return s;
}

int FingerOffset(const NoteFingering& f, const std::string& instrument) {
  for (const auto& span : HandFrameFor(instrument)) {
    if (span.finger == f.finger && span.extended == f.extended &&
        f.position_semitones + span.offset_semitones == f.semitone_on_string) {
      return span.offset_semitones;
    }
  }
  return -100;
}

// Every planned fingering sounds the written note and is a legal hand frame.
void ExpectPlayable(const Score& score, const FingeringPlan& plan, const ScoreInstrument& ins) {
  ASSERT_EQ(plan.notes.size(), score.notes.size());
  for (size_t i = 0; i < score.notes.size(); ++i) {
    const NoteFingering& f = plan.notes[i];
    ASSERT_GE(f.string_index, 0);
    ASSERT_LT(f.string_index, 4);
    EXPECT_EQ(ins.open_string_midi[f.string_index] + f.semitone_on_string,
              score.notes[i].midi_note);
    if (f.finger == 0) {
      EXPECT_EQ(f.semitone_on_string, 0);
    } else {
      EXPECT_NE(FingerOffset(f, ins.name), -100) << "note " << i;
    }
  }
}

// Both notes of every double stop of the built-in piece: adjacent strings, one hand
// position, each a legal stop of the hand frame; two fingers unless one finger stops a fifth.
TEST(PlanFingering, DoubleStopsTakeAdjacentStringsAndAPlayableHand) {
  for (const auto& ins : {Cello(), Violin(), testing::Viola(), testing::Bass()}) {
    auto score = MakeBuiltInPiece("double-stops", ins);
    ASSERT_TRUE(score.ok());
    auto plan = PlanFingering(*score, ins);
    ASSERT_TRUE(plan.ok()) << ins.name << ": " << plan.status().message();
    ExpectPlayable(*score, *plan, ins);
    int fifths_one_finger = 0;
    for (size_t i = 0; i < score->notes.size(); ++i) {
      const ScoreNote& n = score->notes[i];
      const NoteFingering& f = plan->notes[i];
      ASSERT_EQ(f.IsDoubleStop(), n.IsDoubleStop());
      if (!n.IsDoubleStop()) continue;
      ASSERT_EQ(f.second_string_index, f.string_index + 1) << ins.name << " note " << i;
      EXPECT_EQ(ins.open_string_midi[f.second_string_index] + f.second_semitone_on_string,
                n.second_midi_note);
      NoteFingering g{f.second_string_index,
                      f.second_finger,
                      f.position_semitones,
                      f.second_semitone_on_string,
                      f.extended};
      if (g.finger > 0 && FingerOffset(g, ins.name) == -100) g.extended = !g.extended;
      if (g.finger > 0) {
        EXPECT_NE(FingerOffset(g, ins.name), -100) << ins.name << " note " << i;
      }
      if (f.finger > 0 && f.finger == f.second_finger) {
        EXPECT_EQ(f.semitone_on_string, f.second_semitone_on_string);  // a fifth
        ++fifths_one_finger;
      }
    }
    // Strings tuned in fifths: a stopped fifth takes one finger across both strings (the
    // double bass, tuned in fourths, has none).
    const bool in_fifths = ins.open_string_midi[1] - ins.open_string_midi[0] == 7;
    EXPECT_EQ(fifths_one_finger >= 1, in_fifths) << ins.name;
  }
}

// Every chord's two pairs: one hand position, the upper pair on the lower pair's upper
// string (the same finger on the shared note) or on the next two strings, and no finger on
// two places unless it stops a fifth across two neighbouring strings.
TEST(PlanFingering, ChordsHoldEveryFingerInOnePosition) {
  for (const auto& ins : {Cello(), Violin(), testing::Viola(), testing::Bass()}) {
    auto score = MakeBuiltInPiece("chords", ins);
    ASSERT_TRUE(score.ok());
    auto plan = PlanFingering(*score, ins);
    ASSERT_TRUE(plan.ok()) << ins.name << ": " << plan.status().message();
    ExpectPlayable(*score, *plan, ins);
    int chords = 0;
    for (size_t i = 1; i < score->notes.size(); ++i) {
      if (!score->notes[i].chord_upper_pair) continue;
      ++chords;
      const NoteFingering& lo = plan->notes[i - 1];
      const NoteFingering& up = plan->notes[i];
      EXPECT_EQ(up.position_semitones, lo.position_semitones) << ins.name << " note " << i;
      const bool shared = score->notes[i].midi_note == score->notes[i - 1].second_midi_note;
      EXPECT_EQ(up.string_index, lo.second_string_index + (shared ? 0 : 1)) << ins.name;
      if (shared) {
        EXPECT_EQ(up.finger, lo.second_finger) << ins.name;
      }
      // (string, finger, semitone) of every stopped place of the chord.
      std::vector<std::array<int, 3>> places = {
          {lo.string_index, lo.finger, lo.semitone_on_string},
          {lo.second_string_index, lo.second_finger, lo.second_semitone_on_string},
          {up.second_string_index, up.second_finger, up.second_semitone_on_string}};
      if (!shared) places.push_back({up.string_index, up.finger, up.semitone_on_string});
      for (size_t a = 0; a < places.size(); ++a) {
        for (size_t b = a + 1; b < places.size(); ++b) {
          if (places[a][1] == 0 || places[a][1] != places[b][1]) continue;
          EXPECT_EQ(std::abs(places[a][0] - places[b][0]), 1) << ins.name << " note " << i;
          EXPECT_EQ(places[a][2], places[b][2]) << ins.name << " note " << i;
        }
      }
    }
    EXPECT_GE(chords, 4) << ins.name;
  }
}

// A chord whose pairs need two hand positions (A3 + E4 under one finger in second position,
// then A5 + C#6 in the ninth) cannot be held and is an error, though each pair alone is
// playable.
TEST(PlanFingering, ChordThatOneHandCannotHoldIsAnError) {
  Score s;
  s.notes.push_back({57, 0.1, 0.4, 80, 64});
  s.notes.push_back({81, 0.4, 1.0, 80, 85});
  s.duration_s = 1.5;
  ASSERT_TRUE(PlanFingering(s, Violin()).ok());
  s.notes[1].chord_upper_pair = true;
  auto plan = PlanFingering(s, Violin());
  ASSERT_FALSE(plan.ok());
  EXPECT_NE(plan.status().message().find("cannot be held"), std::string::npos)
      << plan.status().message();
}

TEST(PlanFingering, DoubleStopThatNoHandSpansIsAnError) {
  Score s;
  s.notes.push_back({56, 0.1, 0.5, 80, 71});  // G#3 + B4: a tenth, not on adjacent strings
  s.duration_s = 1;
  auto plan = PlanFingering(s, Violin());
  ASSERT_FALSE(plan.ok());
  EXPECT_NE(plan.status().message().find("G#3+B4"), std::string::npos) << plan.status().message();
}

TEST(PlanFingering, LowScaleOnTheCStringUsesFirstPosition) {
  // C2 D2 E2 F2: open, 1, 3, 4 in first position (finger 1 on D).
  const Score s = Notes({{36, 0.5}, {38, 0.5}, {40, 0.5}, {41, 0.5}});
  auto plan = PlanFingering(s, Cello());
  ASSERT_TRUE(plan.ok()) << plan.status().message();
  ExpectPlayable(s, *plan, Cello());
  EXPECT_EQ(plan->notes[0].finger, 0);
  for (int i = 1; i < 4; ++i) {
    EXPECT_EQ(plan->notes[i].string_index, 0);
    EXPECT_EQ(plan->notes[i].position_semitones, 2);
  }
  EXPECT_EQ(plan->notes[1].finger, 1);
  EXPECT_EQ(plan->notes[2].finger, 3);
  EXPECT_EQ(plan->notes[3].finger, 4);
  EXPECT_EQ(plan->num_shifts, 0);
}

TEST(PlanFingering, OpenStringForShortNotesStoppedForLongVibratoNotes) {
  // A3 short: open A string. A3 long: a stopped note (open strings cannot vibrate).
  auto short_plan = PlanFingering(Notes({{57, 0.3}}), Cello());
  ASSERT_TRUE(short_plan.ok());
  EXPECT_EQ(short_plan->notes[0].finger, 0);
  EXPECT_EQ(short_plan->notes[0].string_index, 3);
  auto long_plan = PlanFingering(Notes({{57, 2.0}}), Cello());
  ASSERT_TRUE(long_plan.ok());
  // Cheapest by the documented costs: D string, 3rd finger in 5th-semitone position
  // (0.12 * 5 = 0.60 beats 4th finger in position 4: 0.48 + 0.2 = 0.68).
  EXPECT_EQ(long_plan->notes[0].string_index, 2);
  EXPECT_EQ(long_plan->notes[0].finger, 3);
  EXPECT_EQ(long_plan->notes[0].position_semitones, 5);
  EXPECT_NEAR(long_plan->total_cost, 0.60, 1e-12);
}

TEST(PlanFingering, BuiltInPiecesArePlayableWithFewShifts) {
  for (const auto& ins : {Cello(), Violin(), testing::Viola(), testing::Bass()}) {
    for (const auto& name : BuiltInPieceNames()) {
      auto score = MakeBuiltInPiece(name, ins);
      ASSERT_TRUE(score.ok());
      auto plan = PlanFingering(*score, ins);
      ASSERT_TRUE(plan.ok()) << ins.name << " " << name << ": " << plan.status().message();
      ExpectPlayable(*score, *plan, ins);
      // A player shifts on a minority of notes.
      EXPECT_LT(plan->num_shifts, static_cast<int>(score->notes.size()) / 2)
          << ins.name << " " << name;
    }
  }
}

TEST(PlanFingering, OpenStringPieceUsesOpenStrings) {
  auto score = MakeBuiltInPiece("open-strings", Cello());
  ASSERT_TRUE(score.ok());
  auto plan = PlanFingering(*score, Cello());
  ASSERT_TRUE(plan.ok());
  EXPECT_GE(plan->num_open_strings, 8);
}

TEST(PlanFingering, ShiftCostsTradeOffAgainstPosition) {
  // With a huge shift cost, the planner stays in one position for a melody that
  // fits in it; with zero shift cost it moves to the lowest positions.
  const Score s = Notes({{52, 0.4}, {55, 0.4}, {53, 0.4}, {59, 0.4}, {57, 0.4}});
  FingeringOptions sticky;
  sticky.shift_cost = 100;
  sticky.open_string_cost = 100;
  auto plan = PlanFingering(s, Cello(), sticky);
  ASSERT_TRUE(plan.ok());
  EXPECT_EQ(plan->num_shifts, 0);
  ExpectPlayable(s, *plan, Cello());
}

TEST(PlanFingering, RejectsBadOptionsAndUnplayableNotes) {
  FingeringOptions bad;
  bad.shift_cost = -1;
  EXPECT_FALSE(PlanFingering(Notes({{50, 0.5}}), Cello(), bad).ok());
  bad = {};
  bad.max_position_semitones = 0;
  EXPECT_FALSE(bad.Validate().ok());
  // A5 needs position 18+ on the A string; with max position 5 it is unplayable.
  FingeringOptions low;
  low.max_position_semitones = 5;
  auto plan = PlanFingering(Notes({{81, 0.5}}), Cello(), low);
  ASSERT_FALSE(plan.ok());
  EXPECT_NE(plan.status().message().find("note 81 (A5)"), std::string::npos);
  EXPECT_THROW(HandFrameFor("lute"), std::invalid_argument);
}

}  // namespace
}  // namespace arco::synth
