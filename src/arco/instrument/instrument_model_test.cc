#include "arco/instrument/instrument_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace arco {
namespace {

InstrumentModel Make(InstrumentOptions options) {
  auto model = InstrumentModel::Create(options);
  EXPECT_TRUE(model.ok()) << model.status().message();
  return *model;
}

TEST(ParseInstrumentKind, KnownNamesAndAliases) {
  EXPECT_EQ(*ParseInstrumentKind("cello"), InstrumentKind::kCello);
  EXPECT_EQ(*ParseInstrumentKind("Violin"), InstrumentKind::kViolin);
  EXPECT_EQ(*ParseInstrumentKind("VIOLA"), InstrumentKind::kViola);
  EXPECT_EQ(*ParseInstrumentKind("double_bass"), InstrumentKind::kDoubleBass);
  EXPECT_EQ(*ParseInstrumentKind("contrabass"), InstrumentKind::kDoubleBass);
  EXPECT_STREQ(InstrumentKindName(InstrumentKind::kDoubleBass), "double_bass");
}

TEST(ParseInstrumentKind, UnknownNameIsAClearError) {
  auto kind = ParseInstrumentKind("ukulele");
  ASSERT_FALSE(kind.ok());
  EXPECT_NE(kind.status().message().find("ukulele"), std::string::npos);
  EXPECT_NE(kind.status().message().find("cello"), std::string::npos);
  EXPECT_FALSE(ParseInstrumentKind("").ok());
  EXPECT_FALSE(InstrumentModel::Create("guitar").ok());
}

TEST(InstrumentModel, OpenStringsMatchDomainTable) {
  // DOMAIN.md section 5, low to high, i.e. strings 4..1.
  const struct {
    const char* name;
    double low_to_high[4];
    double length_mm;
  } kTable[] = {
      {"violin", {196.00, 293.66, 440.00, 659.26}, 328},
      {"viola", {130.81, 196.00, 293.66, 440.00}, 370},
      {"cello", {65.41, 98.00, 146.83, 220.00}, 695},
      {"double_bass", {41.20, 55.00, 73.42, 98.00}, 1050},
  };
  for (const auto& row : kTable) {
    auto model = InstrumentModel::Create(row.name);
    ASSERT_TRUE(model.ok());
    ASSERT_EQ(model->num_strings(), 4);
    for (int i = 0; i < 4; ++i) {
      EXPECT_NEAR(model->open_hz(4 - i), row.low_to_high[i], 0.006) << row.name << " " << i;
    }
    EXPECT_EQ(model->string_length_mm(), row.length_mm);
    EXPECT_GT(model->bridge_spacing_mm(), model->nut_spacing_mm());
  }
  EXPECT_EQ(InstrumentModel::Create("cello")->open_note_name(4), "C2");
  EXPECT_EQ(InstrumentModel::Create("violin")->open_note_name(1), "E5");
}

TEST(InstrumentModel, ConcertPitchScalesAllStrings) {
  InstrumentOptions options;
  options.kind = InstrumentKind::kCello;
  options.tuning.a4_hz = 415.0;  // baroque
  const InstrumentModel model = Make(options);
  const InstrumentModel standard = *InstrumentModel::Create("cello");
  for (int s = 1; s <= 4; ++s) {
    EXPECT_NEAR(model.open_hz(s) / standard.open_hz(s), 415.0 / 440.0, 1e-12);
  }
}

TEST(InstrumentModel, ScordaturaByCentsAndByHz) {
  InstrumentOptions options;
  options.kind = InstrumentKind::kCello;
  // Kodaly op. 8: G2 -> F#2, C2 -> B1 (strings 3 and 4 down a semitone).
  options.tuning.offset_cents = {0, 0, -100, -100};
  const InstrumentModel kodaly = Make(options);
  EXPECT_NEAR(kodaly.open_hz(1), 220.0, 1e-9);
  EXPECT_NEAR(kodaly.open_hz(2), 146.832, 1e-3);
  EXPECT_NEAR(kodaly.open_hz(3), 92.499, 1e-3);  // F#2
  EXPECT_NEAR(kodaly.open_hz(4), 61.735, 1e-3);  // B1
  // The range follows the retuned string.
  EXPECT_NEAR(kodaly.max_hz(4), 4 * kodaly.open_hz(4), 1e-9);

  options.tuning.offset_cents.clear();
  options.tuning.open_hz = {0, 0, 0, 64.0};
  const InstrumentModel explicit_hz = Make(options);
  EXPECT_EQ(explicit_hz.open_hz(4), 64.0);
  EXPECT_NEAR(explicit_hz.open_hz(3), 97.9989, 0.0001);  // G2 unchanged
}

TEST(InstrumentModel, PlayableRangeTwoOctavesAndOverride) {
  const InstrumentModel violin = *InstrumentModel::Create("violin");
  EXPECT_NEAR(violin.max_hz(1), 2637.02, 0.01);  // E7
  EXPECT_NEAR(violin.max_hz(4), 4 * 196.0, 0.01);
  InstrumentOptions options;
  options.kind = InstrumentKind::kViolin;
  options.range.max_hz = {3520.0, 0, 0, 0};  // E string up to A7
  EXPECT_EQ(Make(options).max_hz(1), 3520.0);
  options.range.max_hz.clear();
  options.range.semitones_above_open = 31;  // E5 -> B7
  EXPECT_NEAR(Make(options).max_hz(1), 659.255 * std::pow(2.0, 31.0 / 12), 0.01);
}

TEST(InstrumentModel, InvalidOptionsAreErrors) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  InstrumentOptions o;
  o.tuning.a4_hz = nan;
  EXPECT_FALSE(InstrumentModel::Create(o).ok());
  o = {};
  o.tuning.offset_cents = {0, 0, 0};
  auto wrong_size = InstrumentModel::Create(o);
  ASSERT_FALSE(wrong_size.ok());
  EXPECT_NE(wrong_size.status().message().find("3 values"), std::string::npos);
  o = {};
  o.tuning.open_hz = {0, -1, 0, 0};
  EXPECT_FALSE(InstrumentModel::Create(o).ok());
  o = {};
  o.string_length_mm = -5;
  EXPECT_FALSE(InstrumentModel::Create(o).ok());
  o = {};
  o.range.semitones_above_open = 0;
  EXPECT_FALSE(InstrumentModel::Create(o).ok());
  o = {};
  o.range.max_hz = {100, 0, 0, 0};  // below the open A3
  EXPECT_FALSE(InstrumentModel::Create(o).ok());
  o = {};
  o.string_length_mm = 300;  // shorter than the default cello fingerboard
  EXPECT_FALSE(InstrumentModel::Create(o).ok());
}

TEST(InstrumentModel, BadStringNumberThrows) {
  const InstrumentModel cello = *InstrumentModel::Create("cello");
  EXPECT_THROW(cello.open_hz(0), std::invalid_argument);
  EXPECT_THROW(cello.open_hz(5), std::invalid_argument);
  EXPECT_THROW(cello.LateralOffsetAtNutMm(-1), std::invalid_argument);
  EXPECT_THROW(cello.SpdOrderToString(4), std::invalid_argument);
}

TEST(InstrumentModel, KeypointLayoutsFollowSpd) {
  const InstrumentModel cello = *InstrumentModel::Create("cello");
  ASSERT_EQ(cello.keypoint_names().size(), 9u);
  EXPECT_EQ(cello.keypoint_names()[0], "scroll_top");
  EXPECT_EQ(cello.keypoint_names()[6], "end_pin");
  EXPECT_EQ(cello.KeypointIndex("tip"), 8);
  EXPECT_EQ(cello.KeypointIndex("tip_plate"), -1);
  EXPECT_EQ(cello.rigid_keypoints(), (std::vector<int>{0, 1, 2, 3, 4, 5, 6}));
  const InstrumentModel violin = *InstrumentModel::Create("violin");
  ASSERT_EQ(violin.keypoint_names().size(), 7u);
  EXPECT_EQ(violin.keypoint_names()[5], "frog");
  EXPECT_EQ(violin.rigid_keypoints(), (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_EQ(violin.bridge_r(), 4);
}

TEST(InstrumentModel, LateralOffsetsEvenlySpacedLowSidePositive) {
  const InstrumentModel cello = *InstrumentModel::Create("cello");
  EXPECT_DOUBLE_EQ(cello.LateralOffsetAtNutMm(4), cello.nut_spacing_mm() / 2);
  EXPECT_DOUBLE_EQ(cello.LateralOffsetAtNutMm(1), -cello.nut_spacing_mm() / 2);
  EXPECT_DOUBLE_EQ(cello.LateralOffsetAtBridgeMm(4) - cello.LateralOffsetAtBridgeMm(3),
                   cello.bridge_spacing_mm() / 3);
  EXPECT_EQ(cello.SpdOrderToString(0), 4);  // SPD lists the lowest string first
  EXPECT_EQ(cello.SpdOrderToString(3), 1);
}

TEST(InstrumentModel, StringHeightRisesAlongTheFingerboard) {
  const InstrumentModel cello = *InstrumentModel::Create("cello");
  const StringSetup& s = cello.setup();
  EXPECT_DOUBLE_EQ(cello.StringHeightMm(1, 0), s.height_at_nut_mm);
  EXPECT_DOUBLE_EQ(cello.StringHeightMm(1, s.fingerboard_length_mm),
                   s.height_at_fingerboard_end_high_mm);
  EXPECT_DOUBLE_EQ(cello.StringHeightMm(4, 1e4), s.height_at_fingerboard_end_low_mm);
  EXPECT_GT(cello.StringHeightMm(4, 300), cello.StringHeightMm(1, 300));
}

}  // namespace
}  // namespace arco
