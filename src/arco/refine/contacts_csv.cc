#include "arco/refine/contacts_csv.h"

#include <map>
#include <sstream>

#include "arco/util/csv.h"
#include "arco/util/file_io.h"

namespace arco::refine {

Status WriteContactsCsv(const std::string& path, const std::vector<FrameContact>& contacts) {
  return AtomicWriteWith(path, [&](std::ostream& out) {
    out << kContactsCsvHeader << '\n';
    for (size_t f = 0; f < contacts.size(); ++f) {
      const FrameContact& c = contacts[f];
      const bool pressed = c.pressed();
      const Eigen::Vector3d p = pressed ? c.point_in_world_mm : Eigen::Vector3d::Constant(kNaN);
      const int open = c.state == ContactState::kOpenString ? c.string : 0;
      out << f << ',' << ContactStateName(c.state) << ',' << ContactReasonName(c.reason) << ','
          << (pressed ? c.string : 0) << ',' << (pressed ? c.finger : 0) << ',' << c.note << ','
          << FormatCsvDouble(p.x()) << ',' << FormatCsvDouble(p.y()) << ','
          << FormatCsvDouble(p.z()) << ',' << FormatCsvDouble(pressed ? c.from_nut_mm : kNaN) << ','
          << FormatCsvDouble(c.f0_hz) << ',' << FormatCsvDouble(c.confidence) << ','
          << FormatCsvDouble(c.tip_distance_vision_mm) << ','
          << FormatCsvDouble(c.tip_distance_refined_mm) << ',' << open << '\n';
    }
    return Status::Ok();
  });
}

StatusOr<std::vector<ContactRow>> ReadContactsCsv(const std::string& path) {
  ARCO_ASSIGN_OR_RETURN(
      const CsvTable table,
      ReadCsvTable(path,
                   {"frame", "string", "finger", "contact_x_mm", "contact_y_mm", "contact_z_mm"},
                   kContactsCsvHeader));
  std::vector<ContactRow> rows;
  for (const CsvTable::Row& row : table.rows) {
    const std::string where = table.Where(row);
    auto cell = [&](const char* name) -> const std::string* {
      const int c = table.Column(name);
      return c < 0 ? nullptr : &row.cells[c];
    };
    bool ok = true;
    auto integer = [&](const char* name, int64_t fallback) {
      const std::string* c = cell(name);
      int64_t v = fallback;
      if (c && !ParseCsvInt(*c, &v)) ok = false;
      return v;
    };
    auto number = [&](const char* name, double fallback) {
      const std::string* c = cell(name);
      double v = fallback;
      if (c && !ParseCsvDouble(*c, &v)) ok = false;
      return v;
    };
    ContactRow r;
    r.frame = integer("frame", 0);
    const int64_t string = integer("string", 0);
    const int64_t finger = integer("finger", 0);
    const int64_t note = integer("note", -1);
    const int64_t open_string = integer("open_string", 0);
    r.point_mm = Eigen::Vector3d(
        number("contact_x_mm", kNaN), number("contact_y_mm", kNaN), number("contact_z_mm", kNaN));
    r.from_nut_mm = number("from_nut_mm", kNaN);
    r.f0_hz = number("f0_hz", 0);
    r.confidence = number("confidence", 0);
    r.tip_distance_vision_mm = number("tip_distance_vision_mm", kNaN);
    r.tip_distance_refined_mm = number("tip_distance_refined_mm", kNaN);
    if (!ok) return Status::Error(where + "a field is not a number");
    if (const std::string* s = cell("state")) r.state = *s;
    if (const std::string* s = cell("reason")) r.reason = *s;
    if (cell("state") && r.state != "pressed" && r.state != "open" && r.state != "open_string" &&
        r.state != "rest" && r.state != "uncertain") {
      return Status::Error(where + "unknown state '" + r.state + "'");
    }
    if (r.frame < 0 || string < 0 || string > 8 || finger < 0 || finger > 4 || open_string < 0 ||
        open_string > 8) {
      return Status::Error(where + "frame, string or finger out of range");
    }
    r.string = static_cast<int>(string);
    r.finger = static_cast<int>(finger);
    r.note = static_cast<int>(note);
    r.open_string = static_cast<int>(open_string);
    if (r.string > 0 && (r.finger == 0 || !r.point_mm.allFinite())) {
      return Status::Error(where + "presses a string without a finger or point");
    }
    rows.push_back(std::move(r));
  }
  return rows;
}

}  // namespace arco::refine
