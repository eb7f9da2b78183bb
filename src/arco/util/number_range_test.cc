#include "arco/util/number_range.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace arco {
namespace {

TEST(NumberRange, RejectsNonFiniteAndOutside) {
  const NumberRange fps = AboveZero(1000);
  EXPECT_TRUE(fps.Contains(30));
  EXPECT_TRUE(fps.Contains(1000));
  EXPECT_FALSE(fps.Contains(0));
  EXPECT_FALSE(fps.Contains(-1));
  EXPECT_FALSE(fps.Contains(std::nan("")));
  EXPECT_FALSE(fps.Contains(std::numeric_limits<double>::infinity()));
  EXPECT_FALSE(fps.Contains(1e300));
  EXPECT_FALSE(Closed(0, std::numeric_limits<double>::infinity())
                   .Contains(std::numeric_limits<double>::infinity()));
}

TEST(CheckInRange, NamesFieldRangeAndValue) {
  const Status s = CheckInRange("fps", std::nan(""), AboveZero(1000));
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message(), "fps must be a finite number in (0, 1000], got nan");
  EXPECT_EQ(CheckInRange("a4_hz", 500, Closed(400, 480)).message(),
            "a4_hz must be a finite number in [400, 480], got 500");
  EXPECT_TRUE(CheckInRange("a4_hz", 440, Closed(400, 480)).ok());
}

}  // namespace
}  // namespace arco
