#include "arco/calibration/board.h"

#include <gtest/gtest.h>

namespace arco::calibration {
namespace {

TEST(ParseBoardSpec, ReadsChessboard) {
  auto spec = ParseBoardSpec("chessboard:9x6:25");
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  EXPECT_EQ(spec->kind, BoardKind::kChessboard);
  EXPECT_EQ(spec->inner_cols, 9);
  EXPECT_EQ(spec->inner_rows, 6);
  EXPECT_EQ(spec->square_mm, 25);
  EXPECT_EQ(spec->num_points(), 54);
  EXPECT_EQ(spec->ToString(), "chessboard:9x6:25");
  const auto points = spec->PointsInBoard();
  ASSERT_EQ(points.size(), 54u);
  EXPECT_EQ(points[10], Eigen::Vector3d(25, 25, 0));  // row 1, column 1
}

TEST(ParseBoardSpec, ReadsCharucoWithAndWithoutDictionary) {
  auto spec = ParseBoardSpec("charuco:10x7:40:30");
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  EXPECT_EQ(spec->kind, BoardKind::kCharuco);
  EXPECT_EQ(spec->inner_cols, 9);  // squares - 1
  EXPECT_EQ(spec->inner_rows, 6);
  EXPECT_EQ(spec->marker_mm, 30);
  EXPECT_EQ(spec->dictionary, "DICT_4X4_50");
  auto back = ParseBoardSpec(spec->ToString());
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->ToString(), spec->ToString());
  auto dict = ParseBoardSpec("charuco:5x5:20.5:15:DICT_6X6_250");
  ASSERT_TRUE(dict.ok()) << dict.status().message();
  EXPECT_EQ(dict->dictionary, "DICT_6X6_250");
  EXPECT_EQ(dict->square_mm, 20.5);
}

TEST(ParseBoardSpec, RejectsWrongSpecsWithOneReadableLine) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "expected chessboard"},
      {"chess:9x6:25", "unknown board kind 'chess'"},
      {"chessboard:9x6", "expected chessboard"},
      {"chessboard:9x6:25:10", "expected chessboard"},
      {"chessboard:9:25", "is not COLSxROWS"},
      {"chessboard:9x6.5:25", "is not COLSxROWS"},
      {"chessboard:-9x6:25", "is not COLSxROWS"},
      {"chessboard:1x6:25", "board columns (inner corners) must be"},
      {"chessboard:9x101:25", "board rows (inner corners) must be"},
      {"chessboard:9x6:0", "square size (mm) must be"},
      {"chessboard:9x6:nan", "square size 'nan' is not a number"},
      {"chessboard:9x6:1e3", "square size '1e3' is not a number"},
      {"charuco:10x7:40", "expected chessboard"},
      {"charuco:2x7:40:30", "board columns (squares) must be"},
      {"charuco:10x7:40:40", "marker size 40 mm must be smaller"},
      {"charuco:10x7:40:30:DICT_9X9", "unknown ArUco dictionary 'DICT_9X9'"},
  };
  for (const auto& [text, expected] : cases) {
    auto spec = ParseBoardSpec(text);
    ASSERT_FALSE(spec.ok()) << text;
    EXPECT_NE(spec.status().message().find("board '" + text + "'"), std::string::npos)
        << spec.status().message();
    EXPECT_NE(spec.status().message().find(expected), std::string::npos)
        << text << ": " << spec.status().message();
    EXPECT_EQ(spec.status().message().find('\n'), std::string::npos);
  }
}

TEST(BoardSpec, ValidateNamesTheField) {
  BoardSpec spec;
  spec.square_mm = -1;
  EXPECT_NE(spec.Validate().message().find("square size"), std::string::npos);
}

}  // namespace
}  // namespace arco::calibration
