#include "arco/util/csv.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>

#include "arco/util/file_io.h"

namespace arco {

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

bool ParseCsvDouble(const std::string& cell, double* out) {
  if (cell.empty()) {
    *out = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  char* end = nullptr;
  *out = std::strtod(cell.c_str(), &end);
  return end == cell.c_str() + cell.size();
}

bool ParseCsvInt(const std::string& cell, int64_t* out) {
  char* end = nullptr;
  const long long v = std::strtoll(cell.c_str(), &end, 10);
  if (cell.empty() || end != cell.c_str() + cell.size()) return false;
  *out = v;
  return true;
}

std::string FormatCsvDouble(double v) {
  if (!std::isfinite(v)) return "nan";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.17g", v);
  return buf;
}

int CsvTable::Column(const std::string& name) const {
  for (size_t i = 0; i < header.size(); ++i) {
    if (header[i] == name) return static_cast<int>(i);
  }
  return -1;
}

std::string CsvTable::Where(const Row& row) const {
  return path + ":" + std::to_string(row.line) + ": ";
}

StatusOr<CsvTable> ReadCsvTable(const std::string& path,
                                const std::vector<std::string>& required_columns,
                                const std::string& expected_header) {
  ARCO_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  return ParseCsvTable(text, path, required_columns, expected_header);
}

StatusOr<CsvTable> ParseCsvTable(const std::string& text,
                                 const std::string& path,
                                 const std::vector<std::string>& required_columns,
                                 const std::string& expected_header) {
  CsvTable table;
  table.path = path;
  std::istringstream in(text);
  std::string line;
  int line_number = 0;
  auto next_line = [&] {
    if (!std::getline(in, line)) return false;
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  };
  const std::string expected =
      expected_header.empty() ? std::string() : " (expected the header '" + expected_header + "')";
  if (!next_line() || line.empty()) return Status::Error(path + ": empty (no header)" + expected);
  table.header = SplitCsvLine(line);
  for (const std::string& name : required_columns) {
    if (table.Column(name) < 0)
      return Status::Error(path + ": no column '" + name + "' in the header" + expected);
  }
  while (next_line()) {
    if (line.empty()) continue;
    CsvTable::Row row{line_number, SplitCsvLine(line)};
    if (row.cells.size() != table.header.size()) {
      return Status::Error(table.Where(row) + "expected " + std::to_string(table.header.size()) +
                           " fields (as the header), found " + std::to_string(row.cells.size()));
    }
    table.rows.push_back(std::move(row));
  }
  return table;
}

}  // namespace arco
