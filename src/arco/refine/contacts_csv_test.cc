// The contact CSV reader: malformed files are errors naming the file and line; truth
// files with other columns are read by column name.
#include "arco/refine/contacts_csv.h"

#include <gtest/gtest.h>

#include <cmath>

#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"

namespace arco::refine {
namespace {

TEST(ReadContactsCsv, MalformedFilesNameTheFileAndLine) {
  arco::testing::TempDir dir;
  EXPECT_FALSE(ReadContactsCsv(dir / "missing.csv").ok());
  ASSERT_TRUE(AtomicWriteFile(dir / "a.csv", "frame,state\n").ok());
  EXPECT_FALSE(ReadContactsCsv(dir / "a.csv").ok());
  const std::string header = std::string(kContactsCsvHeader) + "\n";
  ASSERT_TRUE(AtomicWriteFile(dir / "b.csv", header + "0,pressed,,1,2,0,1,2\n").ok());
  const auto b = ReadContactsCsv(dir / "b.csv");
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.status().message().find("b.csv:2"), std::string::npos) << b.status().message();
  ASSERT_TRUE(AtomicWriteFile(dir / "c.csv", header + "0,pressed,,1,2,0,x,2,3,4,5,6,7,8,0\n").ok());
  EXPECT_FALSE(ReadContactsCsv(dir / "c.csv").ok());
  ASSERT_TRUE(AtomicWriteFile(dir / "d.csv", header + "0,flying,,1,2,0,1,2,3,4,5,6,7,8,0\n").ok());
  EXPECT_FALSE(ReadContactsCsv(dir / "d.csv").ok());
  ASSERT_TRUE(AtomicWriteFile(dir / "e.csv", header + "0,pressed,,9,2,0,1,2,3,4,5,6,7,8,0\n").ok());
  EXPECT_FALSE(ReadContactsCsv(dir / "e.csv").ok());
  ASSERT_TRUE(AtomicWriteFile(dir / "f.csv",
                              header + "0,rest,unvoiced,0,0,-1,nan,nan,nan,nan,0,0.1,nan,nan,0\n")
                  .ok());
  const auto f = ReadContactsCsv(dir / "f.csv");
  ASSERT_TRUE(f.ok()) << f.status().message();
  EXPECT_TRUE(std::isnan((*f)[0].point_mm.x()));
  // A row with a cell more than the header is as damaged as one cut short.
  ASSERT_TRUE(AtomicWriteFile(dir / "g.csv",
                              header + "0,rest,unvoiced,0,0,-1,nan,nan,nan,nan,0,0.1,nan,nan,0,7\n")
                  .ok());
  const auto g = ReadContactsCsv(dir / "g.csv");
  ASSERT_FALSE(g.ok());
  EXPECT_NE(g.status().message().find("g.csv:2: expected 15 fields"), std::string::npos)
      << g.status().message();
}

TEST(ReadContactsCsv, ReadsTruthContactFilesByColumnName) {
  arco::testing::TempDir dir;
  // synth's truth/contact.csv: other columns, other order, "open_string" for open strings.
  ASSERT_TRUE(AtomicWriteFile(dir / "contact.csv",
                              "frame,time_s,state,string,finger,note,f0_hz,contact_x_mm,"
                              "contact_y_mm,contact_z_mm\n"
                              "0,0.000000,rest,0,0,-1,0.0000,nan,nan,nan\n"
                              "1,0.033333,pressed,2,3,0,220.0000,1.5000,-2.0000,3.2500\n"
                              "2,0.066667,open_string,0,0,1,220.0000,-nan,-nan,-nan\n")
                  .ok());
  const auto rows = ReadContactsCsv(dir / "contact.csv");
  ASSERT_TRUE(rows.ok()) << rows.status().message();
  ASSERT_EQ(rows->size(), 3u);
  EXPECT_EQ((*rows)[1].string, 2);
  EXPECT_EQ((*rows)[1].finger, 3);
  EXPECT_EQ((*rows)[1].point_mm, Eigen::Vector3d(1.5, -2.0, 3.25));
  EXPECT_EQ((*rows)[2].state, "open_string");
  EXPECT_TRUE(std::isnan((*rows)[2].point_mm.x()));
  // A pressed string needs a finger and a point.
  ASSERT_TRUE(AtomicWriteFile(dir / "bad.csv",
                              "frame,string,finger,contact_x_mm,contact_y_mm,contact_z_mm\n"
                              "0,1,0,1,2,3\n")
                  .ok());
  const auto bad = ReadContactsCsv(dir / "bad.csv");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("bad.csv:2"), std::string::npos);
}

}  // namespace
}  // namespace arco::refine
