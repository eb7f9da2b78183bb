#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include "arco/registry/instruments.h"
#include "arco/registry/keypoint_layout.h"

namespace arco {
namespace {

bool StartsWith(const std::string& s, const std::string& prefix) {
  return s.compare(0, prefix.size(), prefix) == 0;
}

// Whether keypoint `n` belongs in group `group` by its name (groups without a naming
// rule accept any name).
bool NameFitsGroup(const std::string& group, const std::string& n) {
  const bool foot = n.find("_toe") != std::string::npos || n.find("_heel") != std::string::npos;
  if (group == "body")
    return !foot && !StartsWith(n, "face_") && n.find("_hand_") == std::string::npos;
  if (group == "left_hand") return StartsWith(n, "left_hand_");
  if (group == "right_hand") return StartsWith(n, "right_hand_");
  if (group == "face") return StartsWith(n, "face_");
  if (group == "feet") return foot;
  if (group == "strings") return StartsWith(n, "string");
  if (group == "bow") return n == "frog" || n == "tip";
  if (group == "instrument") return n != "frog" && n != "tip";
  return true;
}

// Every built-in layout: groups in range, sorted, without repeats; "all" covers every
// point; named groups hold exactly the points their names say.
TEST(KeypointLayoutRegistry, GroupsAreConsistentWithNames) {
  const std::vector<std::string> names = KeypointLayoutNames();
  ASSERT_EQ(names.size(), 7u);
  for (const std::string& name : names) {
    SCOPED_TRACE(name);
    const KeypointLayout& l = *FindKeypointLayout(name);
    EXPECT_EQ(l.name, name);
    std::set<std::string> unique(l.names.begin(), l.names.end());
    EXPECT_EQ(unique.size(), l.names.size()) << "repeated keypoint names";
    for (const KeypointGroup& g : l.groups) {
      SCOPED_TRACE(g.name);
      ASSERT_FALSE(g.indices.empty());
      EXPECT_TRUE(std::is_sorted(g.indices.begin(), g.indices.end()));
      EXPECT_EQ(std::adjacent_find(g.indices.begin(), g.indices.end()), g.indices.end());
      EXPECT_GE(g.indices.front(), 0);
      EXPECT_LT(g.indices.back(), l.size());
      for (int i : g.indices) {
        const std::string& n = l.names[static_cast<size_t>(i)];
        EXPECT_TRUE(NameFitsGroup(g.name, n)) << n;
      }
    }
    ASSERT_NE(l.Group("all"), nullptr);
    EXPECT_EQ(static_cast<int>(l.Group("all")->size()), l.size());
    // The non-"all" groups do not overlap.
    std::set<int> seen;
    for (const KeypointGroup& g : l.groups) {
      if (g.name == "all") continue;
      for (int i : g.indices) EXPECT_TRUE(seen.insert(i).second) << g.name << " " << i;
    }
  }
}

TEST(KeypointLayoutRegistry, WholeBodyConstantsMatchTheLayouts) {
  for (const char* name : {"coco_wholebody_133",
                           "spd_cello",
                           "spd_violin",
                           "spd_cello_contact",
                           "spd_violin_contact"}) {
    SCOPED_TRACE(name);
    const KeypointLayout& l = *FindKeypointLayout(name);
    auto first = [&](const char* group) { return l.Group(group)->front(); };
    auto count = [&](const char* group) { return static_cast<int>(l.Group(group)->size()); };
    EXPECT_EQ(first("body"), wholebody::kBodyFirst);
    EXPECT_EQ(count("body"), wholebody::kNumBody);
    EXPECT_EQ(first("feet"), wholebody::kFeetFirst);
    EXPECT_EQ(count("feet"), wholebody::kNumFeet);
    EXPECT_EQ(first("face"), wholebody::kFaceFirst);
    EXPECT_EQ(count("face"), wholebody::kNumFace);
    EXPECT_EQ(first("left_hand"), wholebody::kLeftHandFirst);
    EXPECT_EQ(first("right_hand"), wholebody::kRightHandFirst);
    EXPECT_EQ(count("left_hand"), wholebody::kNumHandPoints);
    EXPECT_EQ(count("right_hand"), wholebody::kNumHandPoints);
    EXPECT_EQ(l.Find("left_hand_wrist"), wholebody::kLeftHandFirst);
    EXPECT_EQ(l.Find("left_shoulder"), wholebody::kLeftShoulder);
    EXPECT_EQ(l.Find("right_shoulder"), wholebody::kRightShoulder);
    EXPECT_EQ(l.Find("left_wrist"), wholebody::kLeftWrist);
    EXPECT_EQ(l.Find("right_wrist"), wholebody::kRightWrist);
    EXPECT_EQ(l.Find("right_hand_wrist"), wholebody::kRightHandFirst);
    EXPECT_EQ(l.Find("right_hand_little_tip"), wholebody::kNumPoints - 1);
    if (l.size() > wholebody::kNumPoints) {
      EXPECT_EQ(first("instrument"), wholebody::kNumPoints);
      EXPECT_EQ(l.Find("scroll_top"), wholebody::kNumPoints);
    }
  }
  // A hand in the whole body follows hand_21's order.
  const KeypointLayout& hand = *FindKeypointLayout("hand_21");
  const KeypointLayout& body = *FindKeypointLayout("coco_wholebody_133");
  EXPECT_EQ(hand.size(), wholebody::kNumHandPoints);
  for (int k = 0; k < hand.size(); ++k) {
    EXPECT_EQ(body.names[static_cast<size_t>(wholebody::kLeftHandFirst + k)],
              "left_hand_" + hand.names[static_cast<size_t>(k)]);
  }
}

TEST(InstrumentRegistry, ParseAndNameRoundTrip) {
  ASSERT_EQ(AllInstruments().size(), 4u);
  for (const InstrumentInfo& info : AllInstruments()) {
    auto kind = ParseInstrumentKind(info.name);
    ASSERT_TRUE(kind.ok()) << info.name;
    EXPECT_EQ(*kind, info.kind);
    EXPECT_STREQ(InstrumentKindName(info.kind), info.name);
    EXPECT_EQ(&GetInstrumentInfo(info.kind), &info);
  }
  EXPECT_STREQ(InstrumentKindName(InstrumentKind::kDoubleBass), "double_bass");
  // The aliases (documented in instruments.h), case-insensitive.
  for (const char* alias : {"bass", "contrabass", "double-bass", "doublebass", "Double_Bass"}) {
    EXPECT_EQ(*ParseInstrumentKind(alias), InstrumentKind::kDoubleBass) << alias;
  }
  EXPECT_EQ(*ParseInstrumentKind("Violoncello"), InstrumentKind::kCello);
  EXPECT_EQ(*ParseInstrumentKind("VIOLIN"), InstrumentKind::kViolin);
  const auto lute = ParseInstrumentKind("lute");
  ASSERT_FALSE(lute.ok());
  EXPECT_NE(lute.status().message().find("double_bass"), std::string::npos);
  EXPECT_FALSE(ParseInstrumentKind("").ok());
  EXPECT_FALSE(ParseInstrumentKind("any").ok());  // the pitch tracker's, not an instrument
}

TEST(InstrumentRegistry, TablesAreConsistent) {
  std::set<int> programs;
  for (const InstrumentInfo& info : AllInstruments()) {
    SCOPED_TRACE(info.name);
    // Open strings rise by fifths (fourths on the double bass).
    const int step = info.kind == InstrumentKind::kDoubleBass ? 5 : 7;
    for (size_t s = 1; s < 4; ++s) {
      EXPECT_EQ(info.open_midi_low_to_high[s] - info.open_midi_low_to_high[s - 1], step);
    }
    EXPECT_TRUE(programs.insert(info.gm_program).second);
    const KeypointLayout* layout = FindKeypointLayout(info.spd_layout);
    ASSERT_NE(layout, nullptr);
    EXPECT_NE(layout->Group("instrument"), nullptr);
    // The pitch search covers the lowest open string, with room below it.
    const double lowest_hz = 440.0 * std::pow(2.0, (info.open_midi_low_to_high[0] - 69) / 12.0);
    EXPECT_LT(info.pitch_search.min_f0_hz, lowest_hz);
    EXPECT_GT(info.pitch_search.max_f0_hz, 8 * lowest_hz);
    EXPECT_GE(info.pitch_search.analysis_rate_hz, 6 * info.pitch_search.max_f0_hz);
  }
  EXPECT_EQ(GetInstrumentInfo(InstrumentKind::kCello).open_midi_low_to_high[0], 36);  // C2
  EXPECT_STREQ(GetInstrumentInfo(InstrumentKind::kDoubleBass).open_notes_low_to_high[0], "E1");
}

// Every instrument's finger table: finger 1 at offset 0, fingers 1..4 only, the closed
// (non-extended) frame rising with the finger; the per-finger offsets derived from it.
TEST(InstrumentRegistry, FingerTables) {
  for (const InstrumentInfo& info : AllInstruments()) {
    SCOPED_TRACE(info.name);
    ASSERT_FALSE(info.hand_frame.empty());
    EXPECT_EQ(info.hand_frame.front().finger, 1);
    EXPECT_EQ(info.hand_frame.front().offset_semitones, 0);
    int last_closed = -1;
    for (const FingerSpan& span : info.hand_frame) {
      EXPECT_GE(span.finger, 1);
      EXPECT_LE(span.finger, 4);
      EXPECT_GE(span.offset_semitones, 0);
      if (span.extended) continue;
      EXPECT_GE(span.offset_semitones, last_closed);
      last_closed = span.offset_semitones;
    }
    EXPECT_EQ(FingerOffsetSemitones(info.kind, 0), 0);
    EXPECT_EQ(FingerOffsetSemitones(info.kind, 1), 0);
    for (int f = 2; f <= 4; ++f) {
      EXPECT_GE(FingerOffsetSemitones(info.kind, f), FingerOffsetSemitones(info.kind, f - 1));
    }
    EXPECT_EQ(FingerOffsetSemitones(info.kind, 7), FingerOffsetSemitones(info.kind, 4));
    EXPECT_EQ(FingerOffsetSemitones(info.kind, -1), 0);
  }
  auto offsets = [](InstrumentKind kind) {
    std::vector<double> o;
    for (int f = 1; f <= 4; ++f) o.push_back(FingerOffsetSemitones(kind, f));
    return o;
  };
  EXPECT_EQ(offsets(InstrumentKind::kCello), (std::vector<double>{0, 1, 2, 3}));
  EXPECT_EQ(offsets(InstrumentKind::kViolin), (std::vector<double>{0, 2, 4, 5}));
  EXPECT_EQ(offsets(InstrumentKind::kViola), (std::vector<double>{0, 2, 4, 5}));
  // Simandl: the bass hand spans a whole tone; the third finger stops with the fourth.
  EXPECT_EQ(offsets(InstrumentKind::kDoubleBass), (std::vector<double>{0, 1, 2, 2}));
}

// Finger 1's place from a stopping finger: in semitones on the violin and the viola; in mm
// of the first position on the cello and the double bass, the same in the first position
// and more semitones per finger higher up.
TEST(InstrumentRegistry, HandPositionFromAStoppingFinger) {
  for (InstrumentKind kind : {InstrumentKind::kViolin, InstrumentKind::kViola}) {
    EXPECT_DOUBLE_EQ(HandPositionSemitones(kind, 3, 12.0), 12.0 - 4.0);
    EXPECT_DOUBLE_EQ(HandPositionSemitones(kind, 1, 7.5), 7.5);
  }
  for (InstrumentKind kind : {InstrumentKind::kCello, InstrumentKind::kDoubleBass}) {
    SCOPED_TRACE(InstrumentKindName(kind));
    EXPECT_DOUBLE_EQ(HandPositionSemitones(kind, 1, 9.0), 9.0);
    for (int finger = 2; finger <= 4; ++finger) {
      const double offset = FingerOffsetSemitones(kind, finger);
      // First position: finger 1 a whole tone above the open string, as in semitones.
      EXPECT_NEAR(HandPositionSemitones(kind, finger, 2.0 + offset), 2.0, 1e-12);
      // Higher up the same mm span more semitones: finger 1 lies farther below the stop.
      EXPECT_LT(HandPositionSemitones(kind, finger, 12.0 + offset), 12.0);
    }
  }
  // Ten semitones up the cello's A string (SPD cello01, 311 mm from the nut): finger 2 there
  // and finger 3 a whole tone higher move finger 1 by 0.4 semitones, where the semitone
  // frame moves it by one.
  const double f2 = HandPositionSemitones(InstrumentKind::kCello, 2, 10.0);
  const double f3 = HandPositionSemitones(InstrumentKind::kCello, 3, 12.0);
  EXPECT_GT(f3 - f2, 0.3);
  EXPECT_LT(f3 - f2, 0.5);
}

}  // namespace
}  // namespace arco
