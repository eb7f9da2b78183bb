#include "arco/util/csv.h"

#include <gtest/gtest.h>

#include <cmath>

namespace arco {
namespace {

TEST(Csv, SplitKeepsEmptyAndTrailingCells) {
  EXPECT_EQ(SplitCsvLine("a,,b"), (std::vector<std::string>{"a", "", "b"}));
  EXPECT_EQ(SplitCsvLine("a,b,"), (std::vector<std::string>{"a", "b", ""}));
  EXPECT_TRUE(SplitCsvLine("").empty());
}

TEST(Csv, NumbersParseWholeCellsOnly) {
  double d = 0;
  EXPECT_TRUE(ParseCsvDouble("1.25", &d));
  EXPECT_EQ(d, 1.25);
  EXPECT_TRUE(ParseCsvDouble("", &d));
  EXPECT_TRUE(std::isnan(d));
  EXPECT_TRUE(ParseCsvDouble("-nan", &d));
  EXPECT_TRUE(std::isnan(d));
  EXPECT_FALSE(ParseCsvDouble("1.5x", &d));
  int64_t i = 0;
  EXPECT_TRUE(ParseCsvInt("-12", &i));
  EXPECT_EQ(i, -12);
  EXPECT_FALSE(ParseCsvInt("", &i));
  EXPECT_FALSE(ParseCsvInt("3.0", &i));
}

TEST(Csv, FormattedDoublesReadBackExactly) {
  for (double v : {0.1, 1.0 / 3.0, -2.5e-300, 12345.678}) {
    double back = 0;
    ASSERT_TRUE(ParseCsvDouble(FormatCsvDouble(v), &back));
    EXPECT_EQ(back, v);
  }
  EXPECT_EQ(FormatCsvDouble(std::nan("")), "nan");
  EXPECT_EQ(FormatCsvDouble(INFINITY), "nan");
}

}  // namespace
}  // namespace arco
