// The contact CSV format: a method's contacts.csv (written here for the result folder's
// paper/ and arco/, pipeline/result_folder.h) and the one reader of every contact CSV, which
// also reads a synthetic truth's contact.csv (synth/truth_folder.h) by column name. It lives
// in refine/ because both the result folder (pipeline/) and the truth folder (synth/) sit
// above this layer and neither may link the other.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "arco/refine/contact_annotation.h"
#include "arco/util/status.h"

namespace arco::refine {

// contacts.csv: one row per frame; frame = row of the arrays, from 0. string, finger and
// contact_*_mm describe a pressed contact only (0 / NaN otherwise); open_string names the
// sounding open string on open-string frames.
inline constexpr char kContactsCsvHeader[] =
    "frame,state,reason,string,finger,note,contact_x_mm,contact_y_mm,contact_z_mm,from_nut_mm,"
    "f0_hz,confidence,tip_distance_vision_mm,tip_distance_refined_mm,open_string";

// Writes `contacts` (row f = frame f) atomically.
Status WriteContactsCsv(const std::string& path, const std::vector<FrameContact>& contacts);

// One row of a contact CSV: a method's contacts.csv or a synthetic truth's contact.csv.
// Columns are found by header name: frame, string, finger and contact_{x,y,z}_mm are
// required; the others of kContactsCsvHeader (and note, f0_hz of truth files) are read when
// present.
struct ContactRow {
  int64_t frame = 0;
  std::string state;  // pressed, open (open_string in truth files), rest, uncertain; or ""
  std::string reason;
  int string = 0, finger = 0, note = -1, open_string = 0;
  Eigen::Vector3d point_mm = Eigen::Vector3d::Constant(kNaN);
  double from_nut_mm = kNaN, f0_hz = 0, confidence = 0;
  double tip_distance_vision_mm = kNaN, tip_distance_refined_mm = kNaN;
};
// The one contact CSV reader. Errors name the file and line: a missing column, a short
// row, an unparsable number (an empty cell is NaN where a number may be missing), an
// unknown state, a string (0-8) or finger (0-4) out of range, a negative frame, a pressed
// string without a finger or a finite point.
StatusOr<std::vector<ContactRow>> ReadContactsCsv(const std::string& path);

}  // namespace arco::refine
