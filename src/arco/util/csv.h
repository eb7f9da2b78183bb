// Cells of arco's CSV files: comma-separated, one header line, no quoting (no cell holds a
// comma). The formats themselves (headers, columns) are owned by their layers; these are
// only the shared parsing and number spelling, so that every reader treats an empty cell,
// "nan" and a trailing comma the same way.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

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

}  // namespace arco
