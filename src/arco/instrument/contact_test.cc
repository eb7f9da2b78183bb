#include "arco/instrument/contact.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace arco {
namespace {

const InstrumentModel& Cello() {
  static const InstrumentModel model = *InstrumentModel::Create("cello");
  return model;
}

TEST(ContactPoint, OctaveIsExactlyHalfWay) {
  const InstrumentModel& cello = Cello();
  for (int s = 1; s <= 4; ++s) {
    const Contact c = ContactPoint(cello, s, 2 * cello.open_hz(s));
    ASSERT_EQ(c.kind, ContactKind::kStopped);
    EXPECT_DOUBLE_EQ(c.contact_from_bridge_mm, 695.0 / 2);
    EXPECT_DOUBLE_EQ(c.fraction_from_bridge, 0.5);
    EXPECT_NEAR(c.cents_from_open, 1200.0, 1e-9);
  }
  const Contact two_octaves = ContactPoint(cello, 1, 880.0);
  EXPECT_DOUBLE_EQ(two_octaves.contact_from_bridge_mm, 695.0 / 4);
  const InstrumentModel violin = *InstrumentModel::Create("violin");
  EXPECT_DOUBLE_EQ(ContactPoint(violin, 2, 880.0).contact_from_bridge_mm, 164.0);
}

TEST(ContactPoint, CentsMoveTheContactAsDomainSays) {
  // DOMAIN.md: 25 cents mid-string on a cello is about 5 mm.
  const double a = ContactPoint(Cello(), 1, 440.0).contact_from_bridge_mm;
  const double b =
      ContactPoint(Cello(), 1, 440.0 * std::pow(2.0, 25.0 / 1200)).contact_from_bridge_mm;
  EXPECT_NEAR(a - b, 347.5 * (1 - std::pow(2.0, -25.0 / 1200)), 1e-9);
  EXPECT_NEAR(a - b, 5.0, 0.05);
}

TEST(ContactPoint, PitchPositionPitchRoundTrip) {
  for (const char* name : {"violin", "viola", "cello", "double_bass"}) {
    const InstrumentModel model = *InstrumentModel::Create(name);
    for (bool correction : {false, true}) {
      ContactOptions options;
      options.physical_correction = correction;
      for (int s = 1; s <= 4; ++s) {
        // From one semitone above open to the top of the range.
        for (double semis = 1.0; semis <= 24.0; semis += 0.37) {
          const double f = model.open_hz(s) * std::pow(2.0, semis / 12);
          const Contact c = ContactPoint(model, s, f, options);
          ASSERT_EQ(c.kind, ContactKind::kStopped) << name << " s" << s << " " << semis;
          const double back = PitchAtContact(model, s, c.contact_from_bridge_mm, options);
          EXPECT_NEAR(CentsBetween(f, back), 0.0, 1e-6) << name << " s" << s << " " << semis;
        }
      }
    }
  }
}

TEST(ContactPoint, PositionPitchPositionRoundTrip) {
  const InstrumentModel& cello = Cello();
  for (bool correction : {false, true}) {
    ContactOptions options;
    options.physical_correction = correction;
    for (double from_bridge = 180.0; from_bridge < 650.0; from_bridge += 13.7) {
      const double f = PitchAtContact(cello, 2, from_bridge, options);
      const Contact c = ContactPoint(cello, 2, f, options);
      ASSERT_TRUE(c.stopped());
      EXPECT_NEAR(c.contact_from_bridge_mm, from_bridge, 1e-6);
    }
  }
}

TEST(ContactPoint, PhysicalCorrectionMovesTheFingerTowardTheNut) {
  const InstrumentModel& cello = Cello();
  ContactOptions corrected;
  corrected.physical_correction = true;
  const Contact ideal = ContactPoint(cello, 3, 2 * cello.open_hz(3));
  const Contact real = ContactPoint(cello, 3, 2 * cello.open_hz(3), corrected);
  // Pressing sharpens, so the stop is further from the bridge than L/2 ...
  EXPECT_GT(real.stop_from_bridge_mm, ideal.stop_from_bridge_mm);
  // ... by a few cents' worth (the ideal stop would sound this many cents sharp).
  const double sharp_cents = CentsBetween(ideal.stop_from_bridge_mm, real.stop_from_bridge_mm);
  EXPECT_GT(sharp_cents, 0.5);
  EXPECT_LT(sharp_cents, 20.0);
  // The pad centre lies pad_centre_offset_mm further toward the nut.
  EXPECT_NEAR(real.contact_from_bridge_mm - real.stop_from_bridge_mm,
              cello.setup().pad_centre_offset_mm,
              1e-12);
}

TEST(ContactPoint, NoContactKinds) {
  const InstrumentModel& cello = Cello();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(ContactPoint(cello, 1, 220.0).kind, ContactKind::kOpenString);
  EXPECT_EQ(ContactPoint(cello, 1, 220.0 * std::pow(2.0, 35.0 / 1200)).kind,
            ContactKind::kOpenString);
  EXPECT_EQ(ContactPoint(cello, 1, 220.0 * std::pow(2.0, -35.0 / 1200)).kind,
            ContactKind::kOpenString);
  EXPECT_EQ(ContactPoint(cello, 1, 220.0 * std::pow(2.0, 45.0 / 1200)).kind, ContactKind::kStopped);
  EXPECT_EQ(ContactPoint(cello, 1, 200.0).kind, ContactKind::kBelowString);
  EXPECT_EQ(ContactPoint(cello, 1, 880.0 * std::pow(2.0, 45.0 / 1200)).kind,
            ContactKind::kStopped);  // within the range tolerance
  EXPECT_EQ(ContactPoint(cello, 1, 880.0 * std::pow(2.0, 55.0 / 1200)).kind,
            ContactKind::kAboveRange);
  for (double bad : {nan, 0.0, -100.0, std::numeric_limits<double>::infinity()}) {
    const Contact c = ContactPoint(cello, 2, bad);
    EXPECT_EQ(c.kind, ContactKind::kNoPitch);
    EXPECT_FALSE(c.stopped());
    EXPECT_TRUE(std::isnan(c.contact_from_bridge_mm));
  }
  const Contact open = ContactPoint(cello, 2, cello.open_hz(2));
  EXPECT_TRUE(std::isnan(open.contact_from_bridge_mm));
  EXPECT_EQ(open.stop_from_bridge_mm, 695.0);
  EXPECT_STREQ(ContactKindName(ContactKind::kAboveRange), "above_range");
}

TEST(ContactPoint, BadArgumentsThrow) {
  EXPECT_THROW(ContactPoint(Cello(), 0, 220.0), std::invalid_argument);
  EXPECT_THROW(ContactPoint(Cello(), 5, 220.0), std::invalid_argument);
  ContactOptions bad;
  bad.open_tolerance_cents = 100;
  EXPECT_FALSE(bad.Validate().ok());
  EXPECT_THROW(ContactPoint(Cello(), 1, 300.0, bad), std::invalid_argument);
  bad = {};
  bad.range_tolerance_cents = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(bad.Validate().ok());
  EXPECT_TRUE(ContactOptions{}.Validate().ok());
}

TEST(PitchAtContact, OffTheStringIsNaN) {
  EXPECT_TRUE(std::isnan(PitchAtContact(Cello(), 1, 0.0)));
  EXPECT_TRUE(std::isnan(PitchAtContact(Cello(), 1, 700.0)));
  EXPECT_TRUE(std::isnan(PitchAtContact(Cello(), 1, std::nan(""))));
  ContactOptions corrected;
  corrected.physical_correction = true;
  EXPECT_TRUE(std::isnan(PitchAtContact(Cello(), 1, 3.0, corrected)));  // inside the pad
  EXPECT_DOUBLE_EQ(PitchAtContact(Cello(), 1, 347.5), 440.0);
}

TEST(ContactCandidates, OnePerStringHighestFirst) {
  const InstrumentModel& cello = Cello();
  const std::vector<Contact> a3 = ContactCandidates(cello, 220.0);
  ASSERT_EQ(a3.size(), 4u);
  EXPECT_EQ(a3[0].string, 1);
  EXPECT_EQ(a3[0].kind, ContactKind::kOpenString);
  for (int i = 1; i < 4; ++i) EXPECT_EQ(a3[i].kind, ContactKind::kStopped) << i;
  // Each candidate sounds the same pitch.
  for (int i = 1; i < 4; ++i) {
    EXPECT_NEAR(PitchAtContact(cello, a3[i].string, a3[i].contact_from_bridge_mm), 220.0, 1e-9);
  }
  const std::vector<Contact> a4 = ContactCandidates(cello, 440.0);
  EXPECT_EQ(a4[3].kind, ContactKind::kAboveRange);  // C string tops out at C4
}

}  // namespace
}  // namespace arco
