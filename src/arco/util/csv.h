// Cells of arco's CSV files: comma-separated, one header line, no quoting (no cell holds a
// comma). The formats themselves (headers, columns) are owned by their layers; these are
// only the shared parsing and number spelling, so that every reader treats an empty cell,
// "nan" and a trailing comma the same way.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "arco/util/status.h"

namespace arco {

// The cells of one line; a trailing comma is one more (empty) cell.
std::vector<std::string> SplitCsvLine(const std::string& line);
// False when the whole cell is not a number. An empty cell is a missing number (NaN);
// "nan" and "-nan" are NaN too.
bool ParseCsvDouble(const std::string& cell, double* out);
// False when the whole cell is not a base-10 integer (an empty cell is not).
bool ParseCsvInt(const std::string& cell, int64_t* out);
// The shortest text that reads back as the same double (%.17g); NaN and infinities "nan".
std::string FormatCsvDouble(double v);

// A CSV file read strictly, the one way every arco CSV reader reads its rows: a header
// line, then rows each with exactly as many cells as the header (a row cut short or with
// extra cells is an error naming the file and line, never a silently missing value).
// Blank lines are skipped; a "\r" before the newline is dropped.
struct CsvTable {
  struct Row {
    int line = 0;  // 1-based line number in the file
    std::vector<std::string> cells;
  };
  std::string path;
  std::vector<std::string> header;
  std::vector<Row> rows;

  int Column(const std::string& name) const;  // -1 when the header lacks it
  // "PATH:LINE: " for messages about a row.
  std::string Where(const Row& row) const;
};
// Errors name the file: unreadable, empty, a header lacking one of `required_columns`
// (listing the expected header `expected_header` when given), a row with the wrong number
// of cells.
StatusOr<CsvTable> ReadCsvTable(const std::string& path,
                                const std::vector<std::string>& required_columns,
                                const std::string& expected_header = "");
// The same on a file's text already in memory; `path` names it in messages.
StatusOr<CsvTable> ParseCsvTable(const std::string& text,
                                 const std::string& path,
                                 const std::vector<std::string>& required_columns,
                                 const std::string& expected_header = "");

}  // namespace arco
