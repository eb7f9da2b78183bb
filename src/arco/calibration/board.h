// Calibration boards: the spec `arco calibrate --board` takes and the board's points.
//
//   chessboard:COLSxROWS:SQUARE_MM                 COLS x ROWS inner corners (OpenCV's
//                                                  patternSize: 9x6 for a 10 x 7 squares board)
//   charuco:COLSxROWS:SQUARE_MM:MARKER_MM[:DICT]    COLS x ROWS squares (OpenCV's CharucoBoard),
//                                                  (COLS-1) x (ROWS-1) inner corners; DICT one
//                                                  of OpenCV's predefined ArUco dictionaries
//                                                  (default DICT_4X4_50)
//
// Board frame (mm): the board lies in its plane z = 0; point id = row * inner_cols + col
// sits at (col * square_mm, row * square_mm, 0), id 0 being the first corner OpenCV
// reports (chessboard) or ChArUco corner 0.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "arco/util/number_range.h"
#include "arco/util/status.h"

namespace arco::calibration {

enum class BoardKind { kChessboard, kCharuco };

// Declared ranges (the spec's numbers are checked against them).
inline constexpr NumberRange kBoardCornersRange = Closed(2, 100);  // inner corners per side
inline constexpr NumberRange kSquareSizeRangeMm = AboveZero(10000);

struct BoardSpec {
  BoardKind kind = BoardKind::kChessboard;
  int inner_cols = 9, inner_rows = 6;  // inner corners
  double square_mm = 25;
  double marker_mm = 0;                    // ChArUco only: side of the ArUco marker in a square
  std::string dictionary = "DICT_4X4_50";  // ChArUco only

  // Readable message on a bad value (fields named as in the spec text).
  Status Validate() const;
  int num_points() const { return inner_cols * inner_rows; }
  // Every inner corner in the board frame (mm), by id.
  std::vector<Eigen::Vector3d> PointsInBoard() const;
  // "chessboard:9x6:25" / "charuco:10x7:40:30:DICT_4X4_50": parses back to the same spec.
  std::string ToString() const;
};

// Parses and validates a spec (above). Errors quote the text and name the wrong part.
StatusOr<BoardSpec> ParseBoardSpec(const std::string& text);

// The ArUco dictionaries a ChArUco spec may name.
const std::vector<std::string>& CharucoDictionaryNames();

}  // namespace arco::calibration
