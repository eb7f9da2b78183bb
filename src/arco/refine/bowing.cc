#include "arco/refine/bowing.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>

#include "arco/util/csv.h"
#include "arco/util/file_io.h"
#include "arco/util/stats.h"

namespace arco::refine {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;
// Frames on either side over which a frame's bow speed is averaged to tell it moves.
constexpr size_t kMovingWindowFrames = 1;

struct Axes {
  Eigen::Vector3d x, y, z;  // instrument frame axes in the world (strings.h)
};

// The instrument frame of one frame's strings: x along the strings toward the nut, y from
// the highest toward the lowest string at the bridge, z = x cross y (the front).
bool AxesOf(const std::vector<StringSegment>& strings, Axes* axes) {
  if (strings.size() < 2) return false;
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  for (const StringSegment& s : strings) x += s.nut - s.bridge;
  Eigen::Vector3d y = strings.back().bridge - strings.front().bridge;
  if (!(x.norm() > 0)) return false;
  x.normalize();
  y -= y.dot(x) * x;
  if (!(y.norm() > 0)) return false;
  y.normalize();
  axes->x = x;
  axes->y = y;
  axes->z = x.cross(y);
  return axes->z.allFinite();
}

// Closest points of the line p + a u (any a) and the segment q0 + b (q1 - q0), b in [0, 1].
void LineToSegment(const Eigen::Vector3d& p,
                   const Eigen::Vector3d& u,
                   const Eigen::Vector3d& q0,
                   const Eigen::Vector3d& q1,
                   double* a,
                   double* b,
                   double* distance) {
  const Eigen::Vector3d d = q1 - q0;
  const Eigen::Vector3d r = q0 - p;
  const double dd = d.squaredNorm(), ud = u.dot(d);
  const double den = dd - ud * ud;  // u is a unit vector
  double t = den > 1e-12 * dd ? (u.dot(r) * ud - d.dot(r)) / den : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const Eigen::Vector3d q = q0 + t * d;
  *a = u.dot(q - p);
  *b = t;
  *distance = (p + *a * u - q).norm();
}

// The upper median of the finite values (NaN when there are none).
double FiniteMedian(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  return v.empty() ? kNaN : UpperMedian(std::move(v));
}

}  // namespace

const char* BowDirectionName(BowDirection d) {
  switch (d) {
    case BowDirection::kDown:
      return "down";
    case BowDirection::kUp:
      return "up";
    case BowDirection::kNone:
      break;
  }
  return "none";
}

Status BowingOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(
      CheckInRange("bowing min_speed_mm_per_s", min_speed_mm_per_s, kBowMinSpeedRangeMmPerS));
  ARCO_RETURN_IF_ERROR(CheckInRange("bowing max_lift_mm", max_lift_mm, kBowMaxLiftRangeMm));
  ARCO_RETURN_IF_ERROR(CheckInRange("bowing min_stroke_mm", min_stroke_mm, kBowMinStrokeRangeMm));
  ARCO_RETURN_IF_ERROR(CheckInRange(
      "bowing double_stop_margin_deg", double_stop_margin_deg, kBowDoubleStopMarginRangeDeg));
  return CheckInRange("bowing onset_tolerance_s", onset_tolerance_s, kBowOnsetToleranceRangeS);
}

StatusOr<BowingResult> AnalyzeBowing(const InstrumentModel& instrument,
                                     const BowingInput& input,
                                     const BowingOptions& options) {
  ARCO_ASSIGN_OR_RETURN(BowingResult out, AnalyzeBowStrokes(instrument, input, options));
  AddBowingNotes(input.notes, options, &out);
  return out;
}

StatusOr<BowingResult> AnalyzeBowStrokes(const InstrumentModel& instrument,
                                         const BowingInput& input,
                                         const BowingOptions& options) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  const size_t n = input.frog_in_world_mm.size();
  if (input.tip_in_world_mm.size() != n || input.strings_in_world_mm.size() != n) {
    return Status::Error("bowing input: " + std::to_string(n) + " frog frames, " +
                         std::to_string(input.tip_in_world_mm.size()) + " tip frames and " +
                         std::to_string(input.strings_in_world_mm.size()) + " string frames");
  }
  if (!(input.fps > 0 && std::isfinite(input.fps))) {
    return Status::Error("bowing input: fps must be > 0");
  }
  const int num_strings = instrument.num_strings();
  std::vector<double> inclination_rad(static_cast<size_t>(num_strings));
  for (int s = 1; s <= num_strings; ++s) {
    inclination_rad[static_cast<size_t>(s - 1)] = instrument.BowInclinationRad(s);
  }

  BowingResult out;
  out.frames.resize(n);
  std::vector<double> along_mm(n, kNaN);  // contact's place on the bow, mm from the frog
  for (size_t f = 0; f < n; ++f) {
    BowingFrame& bf = out.frames[f];
    bf.time_s = input.start_s + static_cast<double>(f) / input.fps;
    const Eigen::Vector3d& frog = input.frog_in_world_mm[f];
    const Eigen::Vector3d& tip = input.tip_in_world_mm[f];
    const std::vector<StringSegment>& strings = input.strings_in_world_mm[f];
    Axes axes;
    const double length = (tip - frog).norm();
    if (!frog.allFinite() || !tip.allFinite() || !(length > 1.0) ||
        static_cast<int>(strings.size()) != num_strings || !AxesOf(strings, &axes)) {
      continue;
    }
    bf.seen = true;
    const Eigen::Vector3d u = (tip - frog) / length;
    const double uy = u.dot(axes.y), uz = u.dot(axes.z);
    // A line's inclination (its direction's sign does not matter): atan(u_z / u_y).
    const double incl = std::abs(uy) > 1e-12 ? std::atan(uz / uy) : (uz >= 0 ? 1 : -1) * kPi / 2;
    bf.inclination_deg = incl / kDeg;
    // Skew: the bow's angle from the bridge line (y) in the string plane, + toward the nut.
    const double ux = u.dot(axes.x);
    bf.skew_deg = std::atan2(uy >= 0 ? ux : -ux, std::abs(uy)) / kDeg;
    int best = 0;
    for (int s = 1; s < num_strings; ++s) {
      if (std::abs(incl - inclination_rad[static_cast<size_t>(s)]) <
          std::abs(incl - inclination_rad[static_cast<size_t>(best)])) {
        best = s;
      }
    }
    const int string = best + 1;
    // The neighbour on the inclination's side: a double stop when near the midpoint.
    const double own = inclination_rad[static_cast<size_t>(best)];
    const int neighbour =
        incl > own ? string - 1 : string + 1;  // higher inclination: higher string
    int second = 0;
    // The neighbour's share of the contact: 1/2 (midway between the two strings) within
    // the margin of the midpoint, none beyond twice the margin, linear between. A contact
    // that switched from the nearer string to the midpoint at the margin would jump by half
    // the strings' spacing along the bow whenever a noisy inclination crossed it (a double
    // stop's, a crossing's), and the jump would read as speed.
    double share = 0;
    const double margin = options.double_stop_margin_deg * kDeg;
    if (neighbour >= 1 && neighbour <= num_strings) {
      const double mid = 0.5 * (own + inclination_rad[static_cast<size_t>(neighbour - 1)]);
      const double off = std::abs(incl - mid);
      if (off <= margin) second = neighbour;
      share = margin > 0 ? 0.5 * std::clamp((2 * margin - off) / margin, 0.0, 1.0)
                         : (second > 0 ? 0.5 : 0.0);
    }
    const StringSegment& seg = strings[static_cast<size_t>(best)];
    double a = 0, b = 0, distance = 0;
    LineToSegment(frog, u, seg.bridge, seg.nut, &a, &b, &distance);
    double sounding_mm = b * (seg.nut - seg.bridge).norm();
    if (share > 0) {
      const StringSegment& other = strings[static_cast<size_t>(neighbour - 1)];
      double a2 = 0, b2 = 0, distance2 = 0;
      LineToSegment(frog, u, other.bridge, other.nut, &a2, &b2, &distance2);
      a += share * (a2 - a);
      sounding_mm += share * (b2 * (other.nut - other.bridge).norm() - sounding_mm);
      if (second > 0) distance = std::min(distance, distance2);  // it touches both
    }
    bf.lift_mm = distance;
    bf.bow_position = a / length;
    along_mm[f] = a;
    if (distance <= options.max_lift_mm) {
      bf.string = string;
      bf.second_string = second;
      bf.sounding_point_mm = sounding_mm;
    }
  }

  // Speed: central differences of the contact's place on the bow (one-sided at gaps).
  auto seen = [&](size_t f) { return std::isfinite(along_mm[f]); };
  for (size_t f = 0; f < n; ++f) {
    if (!seen(f)) continue;
    const bool prev = f > 0 && seen(f - 1), next = f + 1 < n && seen(f + 1);
    double v = kNaN;
    if (prev && next) {
      v = (along_mm[f + 1] - along_mm[f - 1]) * input.fps / 2;
    } else if (next) {
      v = (along_mm[f + 1] - along_mm[f]) * input.fps;
    } else if (prev) {
      v = (along_mm[f] - along_mm[f - 1]) * input.fps;
    }
    out.frames[f].bow_speed_mm_per_s = v;
  }

  // Strokes: the turning points of the contact's place on the bow, each confirmed only once
  // the bow has gone back min_stroke_mm from it (a zigzag filter: the points' jitter and a
  // slow bow's wobble make no bow change). Frames off the strings take no part.
  std::vector<size_t> on;  // frames on a string, in order
  for (size_t f = 0; f < n; ++f) {
    if (seen(f) && out.frames[f].string > 0) on.push_back(f);
  }
  const double step = options.min_stroke_mm;
  int first_direction = 0;    // +1 down, -1 up; 0 until the bow has moved `step`
  std::vector<size_t> turns;  // frames of the turning points
  {
    int dir = 0;
    size_t lo = 0, hi = 0, ext = 0;  // indices into `on`
    for (size_t i = 0; i < on.size(); ++i) {
      const double p = along_mm[on[i]];
      if (dir == 0) {
        if (p < along_mm[on[lo]]) lo = i;
        if (p > along_mm[on[hi]]) hi = i;
        if (p - along_mm[on[lo]] >= step) {
          dir = first_direction = 1, ext = i;
        } else if (along_mm[on[hi]] - p >= step) {
          dir = first_direction = -1, ext = i;
        }
        continue;
      }
      if (dir * (p - along_mm[on[ext]]) > 0) {
        ext = i;
      } else if (dir * (along_mm[on[ext]] - p) >= step) {
        turns.push_back(ext);
        dir = -dir;
        ext = i;
      }
    }
  }
  // Each turn's instant: where lines through the three frames on either side meet.
  auto time = [&](size_t f) { return out.frames[f].time_s; };
  for (size_t k : turns) {
    std::vector<std::pair<double, double>> before, after;
    for (size_t j = k >= 3 ? k - 3 : 0; j < k; ++j)
      before.emplace_back(time(on[j]), along_mm[on[j]]);
    for (size_t j = k + 1; j < std::min(on.size(), k + 4); ++j) {
      after.emplace_back(time(on[j]), along_mm[on[j]]);
    }
    double t_change = time(on[k]);
    double b0 = 0, b1 = 0, a0 = 0, a1 = 0;
    if (FitLine(before, &b0, &b1) && FitLine(after, &a0, &a1) && std::abs(b1 - a1) > 1e-9) {
      const double lo = k > 0 ? time(on[k - 1]) : time(on[k]);
      const double hi = k + 1 < on.size() ? time(on[k + 1]) : time(on[k]);
      t_change = std::clamp((a0 - b0) / (b1 - a1), lo, hi);
    }
    out.change_times_s.push_back(t_change);
  }
  // Whether the bow moves: its own speed or the mean over the seen frames on a string
  // within kMovingWindowFrames reaches min_speed_mm_per_s. A central difference over one
  // frame carries two points' noise over 1/15 s (tens of mm/s at 6 px of 2D noise), so
  // mid-stroke frames of a slow bow read as still; the mean over 3 frames spans 4 frames'
  // motion, under half the noise (sd), and a bow that stops stays still. Over 5 frames
  // gave the same directions while bowed and more to the 30 ms gaps' lifted bow.
  auto StrokeSpeed = [&](size_t f) {
    double sum = 0;
    int count = 0;
    const size_t lo = f >= kMovingWindowFrames ? f - kMovingWindowFrames : 0;
    const size_t hi = std::min(n - 1, f + kMovingWindowFrames);
    for (size_t g = lo; g <= hi; ++g) {
      const double v = out.frames[g].bow_speed_mm_per_s;
      if (!std::isfinite(v) || out.frames[g].string <= 0) continue;
      sum += v;
      ++count;
    }
    return count > 0 && std::isfinite(out.frames[f].bow_speed_mm_per_s) ? sum / count : 0.0;
  };
  // Directions: each frame on a string takes its stroke's, where the bow moves (or within
  // 1.5 frames of a change); the first frame after each change is marked.
  if (first_direction != 0) {
    size_t next_change = 0;
    int dir = first_direction;
    for (size_t f : on) {
      BowingFrame& bf = out.frames[f];
      while (next_change < out.change_times_s.size() &&
             bf.time_s >= out.change_times_s[next_change]) {
        ++next_change;
        dir = -dir;
        bf.bow_change = true;
      }
      const bool moving = (std::isfinite(bf.bow_speed_mm_per_s) &&
                           std::abs(bf.bow_speed_mm_per_s) >= options.min_speed_mm_per_s) ||
                          std::abs(StrokeSpeed(f)) >= options.min_speed_mm_per_s;
      bool near_change = false;
      for (size_t c = next_change > 0 ? next_change - 1 : 0;
           c < std::min(out.change_times_s.size(), next_change + 1);
           ++c) {
        near_change = near_change || std::abs(bf.time_s - out.change_times_s[c]) * input.fps <= 1.5;
      }
      if (moving || near_change) bf.direction = dir > 0 ? BowDirection::kDown : BowDirection::kUp;
    }
  }

  BowingSummary& sum = out.summary;
  sum.frames = static_cast<int>(n);
  sum.bow_changes = static_cast<int>(out.change_times_s.size());
  std::vector<double> sounding, speeds;
  for (const BowingFrame& bf : out.frames) {
    sum.frames_seen += bf.seen;
    sum.frames_on_string += bf.string > 0;
    if (bf.string > 0) sounding.push_back(bf.sounding_point_mm);
    if (bf.direction != BowDirection::kNone) speeds.push_back(std::abs(bf.bow_speed_mm_per_s));
  }
  sum.median_sounding_point_mm = FiniteMedian(sounding);
  sum.median_speed_mm_per_s = FiniteMedian(speeds);
  return out;
}

void AddBowingNotes(const std::vector<NoteFingering>& notes,
                    const BowingOptions& options,
                    BowingResult* result) {
  BowingResult& out = *result;
  const size_t n = out.frames.size();
  BowingSummary& sum = out.summary;
  out.notes.clear();
  sum.notes_string_disagree = 0;
  sum.bow_changes_at_onsets = 0;
  // Notes: the refinement's, with their frames' bowing.
  for (const NoteFingering& nf : notes) {
    BowingNote note;
    note.note = nf.note;
    note.onset_s = nf.onset_s;
    note.duration_s = nf.duration_s;
    note.fingered_string = nf.string;
    std::map<std::pair<int, int>, int> strings;
    int down = 0, up = 0;
    std::vector<double> speeds, sounding;
    const int64_t first = std::max<int64_t>(0, nf.first_frame);
    const int64_t last = std::min<int64_t>(static_cast<int64_t>(n) - 1, nf.last_frame);
    for (int64_t f = first; f <= last; ++f) {
      const BowingFrame& bf = out.frames[static_cast<size_t>(f)];
      if (!bf.seen) continue;
      if (bf.string > 0) ++strings[{bf.string, bf.second_string}];
      down += bf.direction == BowDirection::kDown;
      up += bf.direction == BowDirection::kUp;
      if (bf.direction != BowDirection::kNone) speeds.push_back(std::abs(bf.bow_speed_mm_per_s));
      sounding.push_back(bf.sounding_point_mm);
      if (!std::isfinite(note.bow_from)) note.bow_from = bf.bow_position;
      note.bow_to = bf.bow_position;
    }
    int most = 0;
    for (const auto& [key, count] : strings) {
      if (count > most) {
        most = count;
        note.bow_string = key.first;
        note.bow_second_string = key.second;
      }
    }
    note.strings_agree = nf.string == 0 || note.bow_string == 0 || nf.string == note.bow_string ||
                         nf.string == note.bow_second_string;
    note.direction = down > up   ? BowDirection::kDown
                     : up > down ? BowDirection::kUp
                                 : BowDirection::kNone;
    if (!speeds.empty()) {
      double total = 0;
      for (double v : speeds) total += v;
      note.mean_speed_mm_per_s = total / static_cast<double>(speeds.size());
    }
    note.sounding_point_mm = FiniteMedian(sounding);
    for (double t : out.change_times_s) {
      const double dt = t - nf.onset_s;
      if (!std::isfinite(note.change_to_onset_s) ||
          std::abs(dt) < std::abs(note.change_to_onset_s)) {
        note.change_to_onset_s = dt;
      }
    }
    sum.notes_string_disagree += note.strings_agree ? 0 : 1;
    out.notes.push_back(note);
  }

  sum.notes = static_cast<int>(out.notes.size());
  for (double t : out.change_times_s) {
    for (const NoteFingering& nf : notes) {
      if (std::abs(t - nf.onset_s) <= options.onset_tolerance_s) {
        ++sum.bow_changes_at_onsets;
        break;
      }
    }
  }
}

Json ToJson(const BowingSummary& s) {
  auto number = [](double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); };
  return {{"frames", s.frames},
          {"frames_seen", s.frames_seen},
          {"frames_on_string", s.frames_on_string},
          {"bow_changes", s.bow_changes},
          {"bow_changes_at_onsets", s.bow_changes_at_onsets},
          {"notes", s.notes},
          {"notes_string_disagree", s.notes_string_disagree},
          {"median_sounding_point_mm", number(s.median_sounding_point_mm)},
          {"median_speed_mm_per_s", number(s.median_speed_mm_per_s)}};
}

Json ToJson(const BowingOptions& o) {
  return {{"min_speed_mm_per_s", o.min_speed_mm_per_s},
          {"max_lift_mm", o.max_lift_mm},
          {"min_stroke_mm", o.min_stroke_mm},
          {"double_stop_margin_deg", o.double_stop_margin_deg},
          {"onset_tolerance_s", o.onset_tolerance_s}};
}

Status WriteBowingCsv(const std::string& path, const std::vector<BowingFrame>& frames) {
  return AtomicWriteWith(path, [&](std::ostream& out) {
    out << kBowingCsvHeader << '\n';
    for (size_t f = 0; f < frames.size(); ++f) {
      const BowingFrame& b = frames[f];
      out << f << ',' << FormatCsvDouble(b.time_s) << ',' << b.string << ',' << b.second_string
          << ',' << FormatCsvDouble(b.inclination_deg) << ',' << FormatCsvDouble(b.skew_deg) << ','
          << FormatCsvDouble(b.lift_mm) << ',' << FormatCsvDouble(b.sounding_point_mm) << ','
          << FormatCsvDouble(b.bow_position) << ',' << FormatCsvDouble(b.bow_speed_mm_per_s) << ','
          << BowDirectionName(b.direction) << ',' << (b.bow_change ? 1 : 0) << '\n';
    }
    return Status::Ok();
  });
}

Status WriteBowingNotesCsv(const std::string& path, const std::vector<BowingNote>& notes) {
  return AtomicWriteWith(path, [&](std::ostream& out) {
    out << kBowingNotesCsvHeader << '\n';
    for (const BowingNote& n : notes) {
      out << n.note << ',' << FormatCsvDouble(n.onset_s) << ',' << FormatCsvDouble(n.duration_s)
          << ',' << n.fingered_string << ',' << n.bow_string << ',' << n.bow_second_string << ','
          << (n.strings_agree ? 1 : 0) << ',' << BowDirectionName(n.direction) << ','
          << FormatCsvDouble(n.mean_speed_mm_per_s) << ',' << FormatCsvDouble(n.sounding_point_mm)
          << ',' << FormatCsvDouble(n.bow_from) << ',' << FormatCsvDouble(n.bow_to) << ','
          << FormatCsvDouble(n.change_to_onset_s) << '\n';
    }
    return Status::Ok();
  });
}

StatusOr<std::vector<BowingFrame>> ReadBowingCsv(const std::string& path) {
  ARCO_ASSIGN_OR_RETURN(const CsvTable table,
                        ReadCsvTable(path, {"frame", "string", "direction", "sounding_point_mm"}));
  std::vector<BowingFrame> frames;
  for (const CsvTable::Row& row : table.rows) {
    const std::string where = table.Where(row);
    auto cell = [&](const char* name) -> const std::string* {
      const int c = table.Column(name);
      return c < 0 ? nullptr : &row.cells[static_cast<size_t>(c)];
    };
    int64_t frame = 0, string = 0;
    if (!ParseCsvInt(*cell("frame"), &frame) || frame != static_cast<int64_t>(frames.size())) {
      return Status::Error(where + "frame must be the row's index " +
                           std::to_string(frames.size()));
    }
    if (!ParseCsvInt(*cell("string"), &string) || string < 0 || string > 6) {
      return Status::Error(where + "string must be an integer in [0, 6]");
    }
    BowingFrame b;
    b.string = static_cast<int>(string);
    const std::string& d = *cell("direction");
    if (d == "down") {
      b.direction = BowDirection::kDown;
    } else if (d == "up") {
      b.direction = BowDirection::kUp;
    } else if (d != "none") {
      return Status::Error(where + "direction must be down, up or none, got \"" + d + "\"");
    }
    if (!ParseCsvDouble(*cell("sounding_point_mm"), &b.sounding_point_mm) ||
        std::isinf(b.sounding_point_mm)) {
      return Status::Error(where + "sounding_point_mm is not a number");
    }
    if (b.string > 0 && !(b.sounding_point_mm >= 0)) {
      return Status::Error(where + "sounding_point_mm must be >= 0 on a string");
    }
    double value = 0;
    if (const std::string* t = cell("time_s"); t && ParseCsvDouble(*t, &value)) b.time_s = value;
    if (const std::string* s2 = cell("second_string")) {
      int64_t v = 0;
      if (!ParseCsvInt(*s2, &v) || v < 0 || v > 6) {
        return Status::Error(where + "second_string must be an integer in [0, 6]");
      }
      b.second_string = static_cast<int>(v);
    }
    if (const std::string* p = cell("bow_position"); p && ParseCsvDouble(*p, &value)) {
      b.bow_position = value;
    }
    b.seen = true;
    frames.push_back(b);
  }
  return frames;
}

StatusOr<std::vector<BowingNote>> ReadBowingNotesCsv(const std::string& path) {
  ARCO_ASSIGN_OR_RETURN(
      const CsvTable table,
      ReadCsvTable(path, SplitCsvLine(kBowingNotesCsvHeader), kBowingNotesCsvHeader));
  std::vector<BowingNote> notes;
  for (const CsvTable::Row& row : table.rows) {
    const std::string where = table.Where(row);
    auto cell = [&](const char* name) -> const std::string& {
      return row.cells[static_cast<size_t>(table.Column(name))];
    };
    BowingNote n;
    int64_t note = 0, fingered = 0, bow = 0, second = 0, agree = 0;
    if (!ParseCsvInt(cell("note"), &note) || note < 0 ||
        !ParseCsvInt(cell("fingered_string"), &fingered) ||
        !ParseCsvInt(cell("bow_string"), &bow) ||
        !ParseCsvInt(cell("bow_second_string"), &second) ||
        !ParseCsvInt(cell("strings_agree"), &agree) || fingered < 0 || fingered > 6 || bow < 0 ||
        bow > 6 || second < 0 || second > 6 || (agree != 0 && agree != 1)) {
      return Status::Error(where + "note, the strings and strings_agree must be small integers");
    }
    n.note = static_cast<int>(note);
    n.fingered_string = static_cast<int>(fingered);
    n.bow_string = static_cast<int>(bow);
    n.bow_second_string = static_cast<int>(second);
    n.strings_agree = agree == 1;
    const std::string& d = cell("direction");
    if (d == "down") {
      n.direction = BowDirection::kDown;
    } else if (d == "up") {
      n.direction = BowDirection::kUp;
    } else if (d != "none") {
      return Status::Error(where + "direction must be down, up or none, got \"" + d + "\"");
    }
    const std::pair<const char*, double*> numbers[] = {
        {"onset_s", &n.onset_s},
        {"duration_s", &n.duration_s},
        {"mean_speed_mm_per_s", &n.mean_speed_mm_per_s},
        {"sounding_point_mm", &n.sounding_point_mm},
        {"bow_from", &n.bow_from},
        {"bow_to", &n.bow_to},
        {"change_to_onset_s", &n.change_to_onset_s}};
    for (const auto& [name, out] : numbers) {
      if (!ParseCsvDouble(cell(name), out) || std::isinf(*out)) {
        return Status::Error(where + name + " is not a number");
      }
    }
    if (!std::isfinite(n.onset_s) || !(n.duration_s >= 0)) {
      return Status::Error(where + "onset_s and duration_s must be finite, duration >= 0");
    }
    notes.push_back(n);
  }
  return notes;
}

}  // namespace arco::refine
