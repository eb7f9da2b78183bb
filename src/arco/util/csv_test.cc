#include "arco/util/csv.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "arco/testing/temp_dir.h"

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

TEST(CsvTable, RejectsRowsCutShortOrTooLong) {
  testing::TempDir dir;
  const std::string path = dir / "t.csv";
  std::ofstream(path) << "a,b,c\r\n1,2,3\n\n4,5\n";
  const StatusOr<CsvTable> cut = ReadCsvTable(path, {"a"});
  ASSERT_FALSE(cut.ok());
  EXPECT_EQ(cut.status().message(), path + ":4: expected 3 fields (as the header), found 2");
  std::ofstream(path) << "a,b,c\n1,2,3,4\n";
  EXPECT_FALSE(ReadCsvTable(path, {"a"}).ok());
  std::ofstream(path) << "a,b,c\n1,2,3\r\n4,,\n";
  const StatusOr<CsvTable> ok = ReadCsvTable(path, {"c", "a"});
  ASSERT_TRUE(ok.ok()) << ok.status().message();
  ASSERT_EQ(ok->rows.size(), 2u);
  EXPECT_EQ(ok->rows[1].line, 3);
  EXPECT_EQ(ok->rows[0].cells[2], "3");
  EXPECT_EQ(ok->Column("c"), 2);
}

TEST(CsvTable, RejectsMissingColumnsAndEmptyFiles) {
  testing::TempDir dir;
  const std::string path = dir / "t.csv";
  std::ofstream(path) << "a,b\n";
  const StatusOr<CsvTable> missing = ReadCsvTable(path, {"a", "z"}, "a,z");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().message(),
            path + ": no column 'z' in the header (expected the header 'a,z')");
  std::ofstream(path) << "";
  EXPECT_FALSE(ReadCsvTable(path, {}).ok());
}

}  // namespace
}  // namespace arco
