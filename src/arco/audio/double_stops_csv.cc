#include "arco/audio/double_stops_csv.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include "arco/util/csv.h"
#include "arco/util/file_io.h"

namespace arco::audio {

std::string FormatDoubleStopsCsv(const std::vector<PolyPitchFrame>& frames) {
  std::string out = std::string(kDoubleStopsCsvHeader) + "\n";
  char line[320];
  for (const PolyPitchFrame& f : frames) {
    const double low = f.count >= 1 ? f.notes[0].f0_hz : 0.0;
    const double high = f.count == 2 ? f.notes[1].f0_hz : 0.0;
    std::snprintf(line,
                  sizeof(line),
                  "%lld,%.6f,%d,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f\n",
                  static_cast<long long>(f.frame),
                  f.time_s,
                  f.count,
                  low,
                  high,
                  f.on_strings[0][0].f0_hz,
                  f.on_strings[0][1].f0_hz,
                  f.on_strings[1][0].f0_hz,
                  f.on_strings[1][1].f0_hz,
                  f.on_strings[2][0].f0_hz,
                  f.on_strings[2][1].f0_hz);
    out += line;
  }
  return out;
}

StatusOr<std::vector<PolyPitchFrame>> ParseDoubleStopsCsv(const std::string& text,
                                                          const std::string& source) {
  ARCO_ASSIGN_OR_RETURN(const CsvTable table,
                        ParseCsvTable(text,
                                      source,
                                      {"frame", "time_s", "notes", "f0_low_hz", "f0_high_hz"},
                                      kDoubleStopsCsvHeader));
  const int frame_col = table.Column("frame"), time_col = table.Column("time_s"),
            count_col = table.Column("notes"), low_col = table.Column("f0_low_hz"),
            high_col = table.Column("f0_high_hz");
  std::array<std::array<int, 2>, kStringPairs> on_cols{};
  for (int s = 1; s <= kStringPairs; ++s) {
    const std::string name = "on_" + std::to_string(s);
    on_cols[s - 1] = {table.Column(name + "_low_hz"), table.Column(name + "_high_hz")};
    if ((on_cols[s - 1][0] < 0) != (on_cols[s - 1][1] < 0)) {
      return Status::Error(source + ": " + name + "_low_hz and " + name +
                           "_high_hz come together (header)");
    }
  }
  std::vector<PolyPitchFrame> frames;
  for (const CsvTable::Row& row : table.rows) {
    PolyPitchFrame f;
    int64_t count = 0;
    double low = 0, high = 0;
    if (!ParseCsvInt(row.cells[frame_col], &f.frame) ||
        !ParseCsvDouble(row.cells[time_col], &f.time_s) || !std::isfinite(f.time_s) ||
        !ParseCsvInt(row.cells[count_col], &count) || !ParseCsvDouble(row.cells[low_col], &low) ||
        !std::isfinite(low) || !ParseCsvDouble(row.cells[high_col], &high) ||
        !std::isfinite(high)) {
      return Status::Error(table.Where(row) + "malformed row (every cell a number)");
    }
    if (f.frame != static_cast<int64_t>(frames.size())) {
      return Status::Error(table.Where(row) + "frame " + std::to_string(f.frame) +
                           " out of order (rows are frames 0, 1, 2, ...)");
    }
    const bool matches = (count == 0 && low == 0 && high == 0) ||
                         (count == 1 && low > 0 && high == 0) ||
                         (count == 2 && low > 0 && high >= low);
    if (!matches) {
      return Status::Error(table.Where(row) +
                           "notes must be 0, 1 or 2 with f0_low_hz and f0_high_hz to match "
                           "(two notes: 0 < f0_low_hz <= f0_high_hz; one: f0_high_hz 0; "
                           "none: both 0)");
    }
    for (int s = 0; s < kStringPairs; ++s) {
      if (on_cols[s][0] < 0) continue;
      double on_low = 0, on_high = 0;
      if (!ParseCsvDouble(row.cells[on_cols[s][0]], &on_low) || !std::isfinite(on_low) ||
          !ParseCsvDouble(row.cells[on_cols[s][1]], &on_high) || !std::isfinite(on_high)) {
        return Status::Error(table.Where(row) + "malformed row (every cell a number)");
      }
      if (!((on_low == 0 && on_high == 0) || (on_low > 0 && on_high >= on_low))) {
        return Status::Error(table.Where(row) + "on_" + std::to_string(s + 1) +
                             "_low_hz and on_" + std::to_string(s + 1) +
                             "_high_hz must be both 0 or 0 < low <= high");
      }
      f.on_strings[s][0].f0_hz = on_low;
      f.on_strings[s][1].f0_hz = on_high;
    }
    f.count = static_cast<int>(count);
    f.notes[0].f0_hz = low;
    f.notes[1].f0_hz = high;
    frames.push_back(f);
  }
  return frames;
}

StatusOr<std::vector<PolyPitchFrame>> ReadDoubleStopsCsv(const std::string& path) {
  ARCO_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  return ParseDoubleStopsCsv(text, path);
}

}  // namespace arco::audio
