#include "arco/calibration/board.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>

namespace arco::calibration {
namespace {

std::vector<std::string> Split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(text);
  while (std::getline(in, part, sep)) parts.push_back(part);
  if (!text.empty() && text.back() == sep) parts.push_back("");
  return parts;
}

// A whole decimal number (no sign, no exponent); false otherwise.
bool ParseNumber(const std::string& text, double* value) {
  if (text.empty() || text.size() > 32) return false;
  for (char c : text)
    if (!(std::isdigit(static_cast<unsigned char>(c)) || c == '.')) return false;
  errno = 0;
  char* end = nullptr;
  *value = std::strtod(text.c_str(), &end);
  return errno == 0 && end == text.c_str() + text.size() && std::isfinite(*value);
}

}  // namespace

const std::vector<std::string>& CharucoDictionaryNames() {
  static const std::vector<std::string> names = {"DICT_4X4_50",
                                                 "DICT_4X4_100",
                                                 "DICT_4X4_250",
                                                 "DICT_4X4_1000",
                                                 "DICT_5X5_50",
                                                 "DICT_5X5_100",
                                                 "DICT_5X5_250",
                                                 "DICT_5X5_1000",
                                                 "DICT_6X6_50",
                                                 "DICT_6X6_100",
                                                 "DICT_6X6_250",
                                                 "DICT_6X6_1000",
                                                 "DICT_7X7_50",
                                                 "DICT_7X7_100",
                                                 "DICT_7X7_250",
                                                 "DICT_7X7_1000",
                                                 "DICT_ARUCO_ORIGINAL"};
  return names;
}

Status BoardSpec::Validate() const {
  const bool charuco = kind == BoardKind::kCharuco;
  // ChArUco's size is in squares: inner corners + 1.
  const int offset = charuco ? 1 : 0;
  const char* unit = charuco ? "squares" : "inner corners";
  ARCO_RETURN_IF_ERROR(CheckInRange(
      std::string("board columns (") + unit + ")",
      inner_cols + offset,
      {kBoardCornersRange.min + offset, kBoardCornersRange.max + offset, false, false}));
  ARCO_RETURN_IF_ERROR(CheckInRange(
      std::string("board rows (") + unit + ")",
      inner_rows + offset,
      {kBoardCornersRange.min + offset, kBoardCornersRange.max + offset, false, false}));
  ARCO_RETURN_IF_ERROR(CheckInRange("square size (mm)", square_mm, kSquareSizeRangeMm));
  if (charuco) {
    ARCO_RETURN_IF_ERROR(CheckInRange("marker size (mm)", marker_mm, kSquareSizeRangeMm));
    if (marker_mm >= square_mm)
      return Status::Error("marker size " + NumberText(marker_mm) +
                           " mm must be smaller than the square size " + NumberText(square_mm) +
                           " mm");
    const auto& names = CharucoDictionaryNames();
    if (std::find(names.begin(), names.end(), dictionary) == names.end())
      return Status::Error("unknown ArUco dictionary '" + dictionary + "' (DICT_4X4_50, ..., " +
                           "DICT_7X7_1000, DICT_ARUCO_ORIGINAL)");
  }
  return Status::Ok();
}

std::vector<Eigen::Vector3d> BoardSpec::PointsInBoard() const {
  std::vector<Eigen::Vector3d> points;
  points.reserve(num_points());
  for (int r = 0; r < inner_rows; ++r)
    for (int c = 0; c < inner_cols; ++c) points.emplace_back(c * square_mm, r * square_mm, 0.0);
  return points;
}

std::string BoardSpec::ToString() const {
  if (kind == BoardKind::kChessboard)
    return "chessboard:" + std::to_string(inner_cols) + "x" + std::to_string(inner_rows) + ":" +
           NumberText(square_mm);
  return "charuco:" + std::to_string(inner_cols + 1) + "x" + std::to_string(inner_rows + 1) + ":" +
         NumberText(square_mm) + ":" + NumberText(marker_mm) + ":" + dictionary;
}

StatusOr<BoardSpec> ParseBoardSpec(const std::string& text) {
  const std::string usage =
      "expected chessboard:COLSxROWS:SQUARE_MM or charuco:COLSxROWS:SQUARE_MM:MARKER_MM[:DICT]";
  auto error = [&](const std::string& what) {
    return Status::Error("board '" + text + "': " + what);
  };
  const std::vector<std::string> parts = Split(text, ':');
  if (parts.empty()) return error(usage);
  BoardSpec spec;
  if (parts[0] == "chessboard") {
    spec.kind = BoardKind::kChessboard;
    if (parts.size() != 3) return error(usage);
  } else if (parts[0] == "charuco") {
    spec.kind = BoardKind::kCharuco;
    if (parts.size() != 4 && parts.size() != 5) return error(usage);
  } else {
    return error("unknown board kind '" + parts[0] + "' (chessboard, charuco); " + usage);
  }
  const std::vector<std::string> size = Split(parts[1], 'x');
  double cols = 0, rows = 0;
  if (size.size() != 2 || !ParseNumber(size[0], &cols) || !ParseNumber(size[1], &rows) ||
      cols != std::floor(cols) || rows != std::floor(rows) || cols > 1e6 || rows > 1e6)
    return error("size '" + parts[1] + "' is not COLSxROWS (whole numbers, e.g. 9x6)");
  const int offset = spec.kind == BoardKind::kCharuco ? 1 : 0;
  spec.inner_cols = static_cast<int>(cols) - offset;
  spec.inner_rows = static_cast<int>(rows) - offset;
  if (!ParseNumber(parts[2], &spec.square_mm))
    return error("square size '" + parts[2] + "' is not a number (mm)");
  if (spec.kind == BoardKind::kCharuco) {
    if (!ParseNumber(parts[3], &spec.marker_mm))
      return error("marker size '" + parts[3] + "' is not a number (mm)");
    if (parts.size() == 5) spec.dictionary = parts[4];
  }
  const Status valid = spec.Validate();
  if (!valid.ok()) return error(valid.message());
  return spec;
}

}  // namespace arco::calibration
