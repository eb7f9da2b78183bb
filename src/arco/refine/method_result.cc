#include "arco/refine/method_result.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "arco/hand/kinematics.h"
#include "arco/mocap/capture.h"
#include "arco/mocap/keypoint_layout.h"
#include "arco/util/atomic_dir.h"
#include "arco/util/file_io.h"

namespace arco::refine {
namespace {

namespace fs = std::filesystem;

constexpr int kLeftHandFirst = 91;
constexpr int kNumWholeBody = 133;

void SetPoint(NpyArray<double>* a, int64_t f, int64_t p, const Eigen::Vector3d& v) {
  for (int c = 0; c < 3; ++c) a->at(f, p, c) = v[c];
}

// Numbers in CSV: shortest round-trip form; NaN as "nan".
std::string Num(double v) {
  if (!std::isfinite(v)) return "nan";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.17g", v);
  return buf;
}

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
          << Num(p.x()) << ',' << Num(p.y()) << ',' << Num(p.z()) << ','
          << Num(pressed ? c.from_nut_mm : kNaN) << ',' << Num(c.f0_hz) << ',' << Num(c.confidence)
          << ',' << Num(c.tip_distance_vision_mm) << ',' << Num(c.tip_distance_refined_mm) << ','
          << open << '\n';
    }
    return Status::Ok();
  });
}

Status WriteFingeringCsv(const std::string& path, const std::vector<NoteFingering>& rows) {
  return AtomicWriteWith(path, [&](std::ostream& out) {
    out << kFingeringCsvHeader << '\n';
    for (const NoteFingering& r : rows) {
      out << r.note << ',' << r.first_frame << ',' << r.last_frame << ',' << Num(r.onset_s) << ','
          << Num(r.duration_s) << ',' << Num(r.f0_hz) << ',' << r.midi_note << ','
          << MidiNoteName(r.midi_note) << ',' << Num(r.cents_off) << ',' << r.state << ','
          << r.string << ',' << r.finger << ',' << Num(r.position_semitones) << ','
          << Num(r.from_nut_mm) << ',' << r.pressed_frames << ',' << r.open_frames << ','
          << r.uncertain_frames << '\n';
    }
    return Status::Ok();
  });
}

bool ParseDouble(const std::string& s, double* out) {
  if (s == "nan" || s == "NaN") {
    *out = kNaN;
    return true;
  }
  char* end = nullptr;
  *out = std::strtod(s.c_str(), &end);
  return !s.empty() && end == s.c_str() + s.size();
}

bool ParseInt(const std::string& s, int64_t* out) {
  char* end = nullptr;
  const long long v = std::strtoll(s.c_str(), &end, 10);
  if (s.empty() || end != s.c_str() + s.size()) return false;
  *out = v;
  return true;
}

}  // namespace

std::string SpdContactLayoutName(const InstrumentModel& model) {
  const bool violin_like =
      model.kind() == InstrumentKind::kViolin || model.kind() == InstrumentKind::kViola;
  return violin_like ? "spd_violin_contact" : "spd_cello_contact";
}

NpyArray<double> BuildSpdPoints(const SpdSources& sources,
                                const std::vector<std::optional<hand::HandPose>>& hands,
                                const std::vector<FrameContact>* contacts) {
  const NpyArray<double>& base = sources.base_points_mm;
  if (sources.instrument == nullptr || base.shape.size() != 3 || base.shape[2] != 3) {
    throw std::invalid_argument("BuildSpdPoints: base points must be (F, P, 3) with an instrument");
  }
  const int64_t frames = base.shape[0];
  const int64_t num_base = base.shape[1];
  const int num_strings = sources.instrument->num_strings();
  if (num_base < kNumWholeBody || static_cast<int64_t>(hands.size()) != frames ||
      static_cast<int64_t>(sources.strings_in_world_mm.size()) != frames ||
      (contacts != nullptr && static_cast<int64_t>(contacts->size()) != frames) ||
      num_strings != 4) {
    throw std::invalid_argument("BuildSpdPoints: frame counts or point counts disagree");
  }
  NpyArray<double> out;
  out.shape = {frames, num_base + 13, 3};
  out.data.assign(static_cast<size_t>(frames * (num_base + 13) * 3), kNaN);
  const Eigen::Vector3d nan = Eigen::Vector3d::Constant(kNaN);
  for (int64_t f = 0; f < frames; ++f) {
    for (int64_t p = 0; p < num_base; ++p) {
      for (int c = 0; c < 3; ++c) out.at(f, p, c) = base.at(f, p, c);
    }
    const auto& h = hands[static_cast<size_t>(f)];
    hand::HandPointsMm points;
    if (h) {
      points = hand::ForwardKinematics(sources.hand_model, *h);
      for (int k = 0; k < hand::kNumHandKeypoints; ++k)
        SetPoint(&out, f, kLeftHandFirst + k, points[k]);
    }
    const auto& strings = sources.strings_in_world_mm[static_cast<size_t>(f)];
    const int64_t extra = num_base;
    if (static_cast<int>(strings.size()) == num_strings) {
      for (int pos = 0; pos < num_strings; ++pos) {  // lowest string first
        const StringSegment& s = strings[static_cast<size_t>(num_strings - 1 - pos)];
        SetPoint(&out, f, extra + 2 * pos, s.nut);
        SetPoint(&out, f, extra + 2 * pos + 1, s.bridge);
      }
    }
    if (contacts == nullptr) continue;
    const FrameContact& c = (*contacts)[static_cast<size_t>(f)];
    if (!c.pressed()) continue;
    SetPoint(&out, f, extra + 8, c.point_in_world_mm);
    if (h && c.finger >= 1 && c.finger <= 4) {
      for (int j = 0; j < 4; ++j) {
        SetPoint(&out,
                 f,
                 extra + 9 + j,
                 points[hand::KeypointIndex(static_cast<hand::Finger>(c.finger), j)]);
      }
    } else {
      for (int j = 0; j < 4; ++j) SetPoint(&out, f, extra + 9 + j, nan);
    }
  }
  return out;
}

NpyArray<double> HandParams(const std::vector<std::optional<hand::HandPose>>& hands) {
  NpyArray<double> out;
  const int64_t n = static_cast<int64_t>(hands.size());
  out.shape = {n, 26};
  out.data.assign(static_cast<size_t>(n * 26), kNaN);
  for (int64_t f = 0; f < n; ++f) {
    const auto& h = hands[static_cast<size_t>(f)];
    if (!h) continue;
    const Eigen::Vector3d aa = h->WristAngleAxis();
    for (int c = 0; c < 3; ++c) {
      out.at(f, c) = aa[c];
      out.at(f, 3 + c) = h->wrist_in_world_mm[c];
    }
    for (int d = 0; d < hand::kNumJointDofs; ++d)
      out.at(f, 6 + d) = h->angles_rad[static_cast<size_t>(d)];
  }
  return out;
}

StatusOr<std::vector<std::optional<hand::HandPose>>> HandsFromParams(const NpyArray<double>& params,
                                                                     const std::string& source) {
  if (params.shape.size() != 2 || params.shape[1] != 26) {
    return Status::Error(source + ": hand parameters must have shape (frames, 26)");
  }
  std::vector<std::optional<hand::HandPose>> out(static_cast<size_t>(params.shape[0]));
  for (int64_t f = 0; f < params.shape[0]; ++f) {
    bool finite = true;
    for (int i = 0; i < 26; ++i) finite = finite && std::isfinite(params.at(f, i));
    if (!finite) continue;
    hand::HandPose pose;
    pose.SetWristAngleAxis(Eigen::Vector3d(params.at(f, 0), params.at(f, 1), params.at(f, 2)));
    pose.wrist_in_world_mm = Eigen::Vector3d(params.at(f, 3), params.at(f, 4), params.at(f, 5));
    for (int d = 0; d < hand::kNumJointDofs; ++d)
      pose.angles_rad[static_cast<size_t>(d)] = params.at(f, 6 + d);
    out[static_cast<size_t>(f)] = pose;
  }
  return out;
}

Status WriteStageFolder(const std::string& result_dir,
                        const std::string& stage,
                        const std::function<Status(const std::string& dir)>& write,
                        Json entry) {
  ARCO_RETURN_IF_ERROR(ReadResultManifest(result_dir).status());  // not some other JSON
  ARCO_RETURN_IF_ERROR(MakeDirectories(result_dir));
  ARCO_RETURN_IF_ERROR(AtomicWriteDirectory(JoinPath(result_dir, stage), write));
  entry["dir"] = stage;
  return RecordStage(result_dir, stage, entry);
}

Status RecordStage(const std::string& result_dir, const std::string& stage, const Json& entry) {
  ARCO_ASSIGN_OR_RETURN(Json manifest, ReadResultManifest(result_dir));
  manifest["format"] = "arco-result";
  if (!manifest.contains("version")) manifest["version"] = 1;
  manifest["stages"][stage] = entry;
  return WriteJsonFile(JoinPath(result_dir, kResultManifestName), manifest);
}

Status WriteMethodResult(const std::string& result_dir, const MethodOutput& output) {
  Json files = {{"points3d", "points3d.npy"}, {"hand_params", "hand_params.npy"}};
  if (!output.contacts.empty()) {
    files["contact"] = "contacts.csv";
    files["fingering"] = "fingering.csv";
  }
  const KeypointLayout* layout = FindKeypointLayout(output.layout);
  auto write = [&](const std::string& dir) -> Status {
    ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(dir, "points3d.npy"), output.points3d));
    ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(dir, "hand_params.npy"), HandParams(output.hands)));
    if (!output.contacts.empty()) {
      ARCO_RETURN_IF_ERROR(WriteContactsCsv(JoinPath(dir, "contacts.csv"), output.contacts));
      ARCO_RETURN_IF_ERROR(WriteFingeringCsv(JoinPath(dir, "fingering.csv"), output.fingering));
    }
    return Status::Ok();
  };
  return WriteStageFolder(result_dir,
                          output.method,
                          write,
                          {{"files", files},
                           {"layout", output.layout},
                           {"keypoint_names", layout ? layout->names : std::vector<std::string>()},
                           {"units", "mm"},
                           {"options", output.options},
                           {"summary", output.summary}});
}

StatusOr<std::vector<ContactRow>> ReadContactsCsv(const std::string& path) {
  ARCO_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line) || line != kContactsCsvHeader) {
    return Status::Error(path + ": not a contacts.csv (expected header '" +
                         std::string(kContactsCsvHeader) + "')");
  }
  std::vector<ContactRow> rows;
  int line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.empty()) continue;
    std::vector<std::string> cells;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    if (!line.empty() && line.back() == ',') cells.push_back("");
    const std::string where = path + ":" + std::to_string(line_number) + ": ";
    if (cells.size() != 15) {
      return Status::Error(where + "expected 15 fields, found " + std::to_string(cells.size()));
    }
    ContactRow r;
    int64_t i0 = 0, i3 = 0, i4 = 0, i5 = 0, i14 = 0;
    double d[8];
    bool ok = ParseInt(cells[0], &i0) && ParseInt(cells[3], &i3) && ParseInt(cells[4], &i4) &&
              ParseInt(cells[5], &i5) && ParseInt(cells[14], &i14);
    for (int k = 0; k < 8 && ok; ++k) ok = ParseDouble(cells[static_cast<size_t>(6 + k)], &d[k]);
    if (!ok) return Status::Error(where + "a field is not a number");
    if (cells[1] != "pressed" && cells[1] != "open" && cells[1] != "rest" &&
        cells[1] != "uncertain") {
      return Status::Error(where + "unknown state '" + cells[1] + "'");
    }
    if (i3 < 0 || i3 > 4 || i4 < 0 || i4 > 4 || i14 < 0 || i14 > 4) {
      return Status::Error(where + "string or finger out of range");
    }
    r.frame = i0;
    r.state = cells[1];
    r.reason = cells[2];
    r.string = static_cast<int>(i3);
    r.finger = static_cast<int>(i4);
    r.note = static_cast<int>(i5);
    r.open_string = static_cast<int>(i14);
    r.point_mm = Eigen::Vector3d(d[0], d[1], d[2]);
    r.from_nut_mm = d[3];
    r.f0_hz = d[4];
    r.confidence = d[5];
    r.tip_distance_vision_mm = d[6];
    r.tip_distance_refined_mm = d[7];
    rows.push_back(r);
  }
  return rows;
}

}  // namespace arco::refine
