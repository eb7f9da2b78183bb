#include "arco/pipeline/result_folder.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>

#include "arco/util/file_io.h"
#include "arco/util/output_set.h"

namespace arco::pipeline {
namespace {

// File names inside the stage folders.
constexpr char kPoints3dFile[] = "points3d.npy";
constexpr char kPoints3dRawFile[] = "points3d_raw.npy";
constexpr char kReprojectionRmsFile[] = "reprojection_rms_px.npy";
constexpr char kInlierCountFile[] = "inlier_count.npy";
constexpr char kViewCountFile[] = "view_count.npy";
constexpr char kInlierMaskFile[] = "inlier_mask.npy";
constexpr char kStringsFile[] = "strings.npy";
constexpr char kKeypointsFile[] = "keypoints.npy";
constexpr char kHandParamsFile[] = "hand_params.npy";
constexpr char kBoneLengthsFile[] = "bone_lengths_mm.npy";
constexpr char kPitchCsvFile[] = "pitch.csv";
constexpr char kNotesCsvFile[] = "notes.csv";
constexpr char kContactsCsvFile[] = "contacts.csv";
constexpr char kFingeringCsvFile[] = "fingering.csv";
constexpr int kHandParamsColumns = 6 + hand::kNumJointDofs;  // angle-axis, wrist, joints

// Numbers in CSV: shortest round-trip form; NaN as "nan".
std::string Num(double v) {
  if (!std::isfinite(v)) return "nan";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.17g", v);
  return buf;
}

Status WriteContactsCsv(const std::string& path,
                        const std::vector<refine::FrameContact>& contacts) {
  return AtomicWriteWith(path, [&](std::ostream& out) {
    out << kContactsCsvHeader << '\n';
    for (size_t f = 0; f < contacts.size(); ++f) {
      const refine::FrameContact& c = contacts[f];
      const bool pressed = c.pressed();
      const Eigen::Vector3d p = pressed ? c.point_in_world_mm : Eigen::Vector3d::Constant(kNaN);
      const int open = c.state == refine::ContactState::kOpenString ? c.string : 0;
      out << f << ',' << refine::ContactStateName(c.state) << ','
          << refine::ContactReasonName(c.reason) << ',' << (pressed ? c.string : 0) << ','
          << (pressed ? c.finger : 0) << ',' << c.note << ',' << Num(p.x()) << ',' << Num(p.y())
          << ',' << Num(p.z()) << ',' << Num(pressed ? c.from_nut_mm : kNaN) << ',' << Num(c.f0_hz)
          << ',' << Num(c.confidence) << ',' << Num(c.tip_distance_vision_mm) << ','
          << Num(c.tip_distance_refined_mm) << ',' << open << '\n';
    }
    return Status::Ok();
  });
}

Status WriteFingeringCsv(const std::string& path, const std::vector<refine::NoteFingering>& rows) {
  return AtomicWriteWith(path, [&](std::ostream& out) {
    out << kFingeringCsvHeader << '\n';
    for (const refine::NoteFingering& r : rows) {
      out << r.note << ',' << r.first_frame << ',' << r.last_frame << ',' << Num(r.onset_s) << ','
          << Num(r.duration_s) << ',' << Num(r.f0_hz) << ',' << r.midi_note << ','
          << refine::MidiNoteName(r.midi_note) << ',' << Num(r.cents_off) << ',' << r.state << ','
          << r.string << ',' << r.finger << ',' << Num(r.position_semitones) << ','
          << Num(r.from_nut_mm) << ',' << r.pressed_frames << ',' << r.open_frames << ','
          << r.uncertain_frames << '\n';
    }
    return Status::Ok();
  });
}

std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

// An empty cell is a missing number (NaN); "nan" / "-nan" too.
bool ParseDouble(const std::string& s, double* out) {
  if (s.empty()) {
    *out = kNaN;
    return true;
  }
  char* end = nullptr;
  *out = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size();
}

bool ParseInt(const std::string& s, int64_t* out) {
  char* end = nullptr;
  const long long v = std::strtoll(s.c_str(), &end, 10);
  if (s.empty() || end != s.c_str() + s.size()) return false;
  *out = v;
  return true;
}

Status Expect(bool ok, const std::string& path, const std::string& what) {
  return ok ? Status::Ok() : Status::Error(path + ": " + what);
}

}  // namespace

std::string ResultFolder::ManifestPath() const { return JoinPath(dir_, kResultManifestName); }

std::string ResultFolder::StagePath(const std::string& stage, const std::string& file) const {
  return JoinPath(JoinPath(dir_, stage), file);
}

std::string ResultFolder::Points3dPath(const std::string& stage) const {
  return StagePath(stage, kPoints3dFile);
}
std::string ResultFolder::InstrumentStringsPath() const {
  return StagePath(kInstrumentStage, kStringsFile);
}
std::string ResultFolder::InstrumentKeypointsPath() const {
  return StagePath(kInstrumentStage, kKeypointsFile);
}
std::string ResultFolder::HandParamsPath() const { return StagePath(kHandStage, kHandParamsFile); }
std::string ResultFolder::BoneLengthsPath() const {
  return StagePath(kHandStage, kBoneLengthsFile);
}

std::string ResultFolder::ContactsPath(const std::string& method) const {
  return StagePath(method, kContactsCsvFile);
}

StatusOr<Json> ResultFolder::ReadManifest() const {
  const std::string path = ManifestPath();
  if (!FileExists(path)) return Json::object();
  ARCO_ASSIGN_OR_RETURN(Json j, ReadJsonFile(path));
  if (!j.is_object() || j.value("format", "") != "arco-result") {
    return Status::Error(path + ": not an arco result manifest (\"format\": \"arco-result\")");
  }
  return j;
}

StatusOr<ResultHeader> ResultFolder::ReadHeader() const {
  ARCO_ASSIGN_OR_RETURN(const Json result, ReadManifest());
  ResultHeader h;
  if (result.contains("keypoint_names"))
    h.keypoint_names = result["keypoint_names"].get<std::vector<std::string>>();
  h.units = result.value("units", std::string("unknown"));
  if (result.contains("fps") && result["fps"].is_number()) h.fps = result["fps"].get<double>();
  if (result.contains("frames")) {
    h.frame_first = result["frames"].value("first", int64_t{1});
    h.frame_count = result["frames"].value("count", int64_t{0});
  }
  return h;
}

StatusOr<bool> ResultFolder::HasStage(const std::string& stage) const {
  ARCO_ASSIGN_OR_RETURN(const Json result, ReadManifest());
  return result.contains("stages") && result["stages"].contains(stage);
}

StatusOr<std::vector<PointStage>> ResultFolder::PointStages() const {
  ARCO_ASSIGN_OR_RETURN(const Json result, ReadManifest());
  if (!result.contains("stages") || !result["stages"].is_object()) {
    return Status::Error(ManifestPath() + ": no stages (run arco triangulate first)");
  }
  std::vector<PointStage> out;
  for (auto it = result["stages"].begin(); it != result["stages"].end(); ++it) {
    const Json& sj = it.value();
    if (!sj.contains("files") || !sj["files"].contains("points3d")) continue;
    PointStage s;
    s.name = it.key();
    const std::string dir = JoinPath(dir_, sj.value("dir", s.name));
    s.points3d_path = JoinPath(dir, sj["files"]["points3d"].get<std::string>());
    if (sj.contains("keypoint_names"))
      s.keypoint_names = sj["keypoint_names"].get<std::vector<std::string>>();
    if (sj["files"].contains("contact"))
      s.contacts_path = JoinPath(dir, sj["files"]["contact"].get<std::string>());
    out.push_back(std::move(s));
  }
  return out;
}

namespace {

// `manifest` with "stages"."<stage>" = entry (the other stages kept).
Json WithStage(Json manifest, const std::string& stage, const Json& entry) {
  manifest["format"] = "arco-result";
  if (!manifest.contains("version")) manifest["version"] = 1;
  manifest["stages"][stage] = entry;
  return manifest;
}

// A stage folder is the result's own output: an existing one is always replaced.
FolderReplace OwnStageFolder() {
  FolderReplace r;
  r.overwrite = true;
  return r;
}

}  // namespace

Status ResultFolder::CheckWritable() const {
  FolderReplace r;
  r.overwrite = true;  // stage folders of a result are replaced; other folders left alone
  r.marker = kResultManifestName;
  r.kind = "result folder";
  return CheckOutputFolder(dir_, r);
}

Status ResultFolder::WriteStageFolder(const std::string& stage,
                                      const std::function<Status(const std::string& dir)>& write,
                                      Json entry) const {
  ARCO_ASSIGN_OR_RETURN(const Json manifest, ReadManifest());  // not some other JSON
  ARCO_RETURN_IF_ERROR(MakeDirectories(dir_));
  // The folder and result.json change together or not at all.
  OutputSet outputs;
  ARCO_ASSIGN_OR_RETURN(const std::string tmp_dir,
                        outputs.AddFolder(JoinPath(dir_, stage), OwnStageFolder()));
  ARCO_ASSIGN_OR_RETURN(const std::string tmp_manifest, outputs.AddFile(ManifestPath()));
  ARCO_RETURN_IF_ERROR(write(tmp_dir));
  entry["dir"] = stage;
  ARCO_RETURN_IF_ERROR(WriteJsonFile(tmp_manifest, WithStage(manifest, stage, entry)));
  return outputs.Commit();
}

// ---- triangulation/

Status ResultFolder::WriteTriangulation(const CaptureManifest& manifest,
                                        const KeypointLayout& layout,
                                        const SequenceTriangulation& raw,
                                        const NpyArray<double>& points3d_filtered,
                                        const TriangulationRecord& record) const {
  ARCO_ASSIGN_OR_RETURN(Json result, ReadManifest());
  ARCO_RETURN_IF_ERROR(MakeDirectories(dir_));
  // triangulation/ and result.json change together or not at all.
  OutputSet outputs;
  ARCO_ASSIGN_OR_RETURN(const std::string stage_tmp,
                        outputs.AddFolder(JoinPath(dir_, kTriangulationStage), OwnStageFolder()));
  ARCO_ASSIGN_OR_RETURN(const std::string manifest_tmp, outputs.AddFile(ManifestPath()));
  auto write_all = [&](const std::string& tmp_dir) -> Status {
    ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(tmp_dir, kPoints3dFile), points3d_filtered));
    ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(tmp_dir, kPoints3dRawFile), raw.points3d));
    ARCO_RETURN_IF_ERROR(
        WriteNpy(JoinPath(tmp_dir, kReprojectionRmsFile), raw.rms_reprojection_px));
    ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(tmp_dir, kInlierCountFile), raw.num_inliers));
    ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(tmp_dir, kViewCountFile), raw.num_views));
    ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(tmp_dir, kInlierMaskFile), raw.inlier_mask));
    return Status::Ok();
  };
  ARCO_RETURN_IF_ERROR(write_all(stage_tmp));

  result["format"] = "arco-result";
  result["version"] = 1;
  result["capture"] = record.capture_dir;
  result["name"] = manifest.name;
  result["instrument"] = manifest.instrument;
  result["fps"] = manifest.fps;
  result["frames"] = {{"first", manifest.frame_first}, {"count", manifest.frame_count}};
  result["units"] = record.units;
  result["layout"] = layout.name;
  result["keypoint_names"] = layout.names;
  Json cams = Json::array();
  for (const auto& c : manifest.cameras) cams.push_back(c.name);
  result["cameras"] = cams;
  result["stages"][kTriangulationStage] = {{"dir", kTriangulationStage},
                                           {"files",
                                            {{"points3d", kPoints3dFile},
                                             {"points3d_raw", kPoints3dRawFile},
                                             {"reprojection_rms_px", kReprojectionRmsFile},
                                             {"inlier_count", kInlierCountFile},
                                             {"view_count", kViewCountFile},
                                             {"inlier_mask", kInlierMaskFile}}},
                                           {"options", record.options},
                                           {"summary", ToJson(record.summary)}};
  ARCO_RETURN_IF_ERROR(WriteJsonFile(manifest_tmp, result));
  return outputs.Commit();
}

StatusOr<NpyArray<double>> ResultFolder::ReadPoints3d(const std::string& stage) const {
  return ReadNpy<double>(Points3dPath(stage));
}

// ---- instrument/

Status ResultFolder::WriteInstrument(const InstrumentRecord& r) const {
  Json entry = {{"files", {{"strings", kStringsFile}, {"keypoints", kKeypointsFile}}},
                {"instrument", r.instrument},
                {"a4_hz", r.a4_hz},
                {"world_units_per_mm", r.world_units_per_mm},
                {"units", "mm"},
                {"keypoint_names", r.keypoint_names},
                {"summary", ToJson(r.summary)}};
  return WriteStageFolder(
      kInstrumentStage,
      [&](const std::string& dir) -> Status {
        ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(dir, kStringsFile), r.strings_mm));
        return WriteNpy(JoinPath(dir, kKeypointsFile), r.keypoints_mm);
      },
      entry);
}

StatusOr<double> ResultFolder::ReadWorldUnitsPerMm() const {
  ARCO_ASSIGN_OR_RETURN(const Json manifest, ReadManifest());
  const double s = manifest.contains("stages") && manifest["stages"].contains(kInstrumentStage)
                       ? JsonNumberOrNaN(manifest["stages"][kInstrumentStage].value(
                             "world_units_per_mm", Json()))
                       : kNaN;
  if (!(s > 0)) {
    return Status::Error(ManifestPath() +
                         ": no instrument stage with world_units_per_mm (run `arco run` first)");
  }
  return s;
}

StatusOr<InstrumentRecord> ResultFolder::ReadInstrument() const {
  ARCO_ASSIGN_OR_RETURN(const Json manifest, ReadManifest());
  InstrumentRecord r;
  ARCO_ASSIGN_OR_RETURN(r.world_units_per_mm, ReadWorldUnitsPerMm());
  const Json& inst = manifest["stages"][kInstrumentStage];
  r.instrument = inst.value("instrument", std::string());
  r.a4_hz = JsonNumberOrNaN(inst.value("a4_hz", Json(440.0)));
  if (inst.contains("keypoint_names") && inst["keypoint_names"].is_array()) {
    for (const Json& n : inst["keypoint_names"]) {
      if (n.is_string()) r.keypoint_names.push_back(n.get<std::string>());
    }
  }
  ARCO_ASSIGN_OR_RETURN(r.strings_mm, ReadNpy<double>(InstrumentStringsPath()));
  ARCO_ASSIGN_OR_RETURN(r.keypoints_mm, ReadNpy<double>(InstrumentKeypointsPath()));
  return r;
}

// ---- hand/

Status ResultFolder::WriteHand(const HandRecord& r) const {
  NpyArray<double> lengths;
  lengths.shape = {hand::kNumHandKeypoints};
  lengths.data.assign(r.bone_lengths_mm.begin(), r.bone_lengths_mm.end());
  Json entry = {
      {"files", {{"hand_params", kHandParamsFile}, {"bone_lengths_mm", kBoneLengthsFile}}},
      {"side", "left"},
      {"units", "mm"},
      {"summary", ToJson(r.summary)}};
  return WriteStageFolder(
      kHandStage,
      [&](const std::string& dir) -> Status {
        ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(dir, kHandParamsFile), HandParams(r.hands)));
        return WriteNpy(JoinPath(dir, kBoneLengthsFile), lengths);
      },
      entry);
}

StatusOr<HandRecord> ResultFolder::ReadHand() const {
  const std::string hands_path = HandParamsPath();
  const std::string bones_path = BoneLengthsPath();
  ARCO_ASSIGN_OR_RETURN(NpyArray<double> params, ReadNpy<double>(hands_path));
  ARCO_ASSIGN_OR_RETURN(NpyArray<double> bones, ReadNpy<double>(bones_path));
  ARCO_RETURN_IF_ERROR(Expect(bones.shape == std::vector<int64_t>{hand::kNumHandKeypoints},
                              bones_path,
                              "expected 21 bone lengths"));
  HandRecord r;
  ARCO_ASSIGN_OR_RETURN(r.hands, HandsFromParams(params, hands_path));
  for (int k = 0; k < hand::kNumHandKeypoints; ++k)
    r.bone_lengths_mm[static_cast<size_t>(k)] = bones.data[static_cast<size_t>(k)];
  return r;
}

// ---- pitch.csv, notes.csv

Status ResultFolder::WritePitch(const PitchRecord& r) const {
  ARCO_ASSIGN_OR_RETURN(const Json manifest, ReadManifest());
  ARCO_RETURN_IF_ERROR(MakeDirectories(dir_));
  // pitch.csv, notes.csv and result.json change together or not at all.
  OutputSet outputs;
  ARCO_ASSIGN_OR_RETURN(const std::string pitch_tmp, outputs.AddFile(PitchPath()));
  ARCO_ASSIGN_OR_RETURN(const std::string notes_tmp,
                        outputs.AddFile(JoinPath(dir_, kNotesCsvFile)));
  ARCO_ASSIGN_OR_RETURN(const std::string manifest_tmp, outputs.AddFile(ManifestPath()));
  ARCO_RETURN_IF_ERROR(audio::WritePitchCsv(pitch_tmp, r.frames));
  ARCO_RETURN_IF_ERROR(audio::WriteNotesCsv(notes_tmp, r.notes));
  const Json entry = {{"dir", "."},
                      {"files", {{"pitch", kPitchCsvFile}, {"notes", kNotesCsvFile}}},
                      {"a4_hz", r.a4_hz},
                      {"audio", r.summary.audio},
                      {"summary", ToJson(r.summary)}};
  ARCO_RETURN_IF_ERROR(WriteJsonFile(manifest_tmp, WithStage(manifest, kPitchStage, entry)));
  return outputs.Commit();
}

std::string ResultFolder::PitchPath() const { return JoinPath(dir_, kPitchCsvFile); }

StatusOr<std::vector<audio::PitchFrame>> ResultFolder::ReadPitch() const {
  return audio::ReadPitchCsv(PitchPath());
}

StatusOr<std::vector<audio::Note>> ResultFolder::ReadNotes() const {
  const std::string path = JoinPath(dir_, kNotesCsvFile);
  if (!FileExists(path)) return std::vector<audio::Note>();
  return audio::ReadNotesCsv(path);
}

// ---- vision/ paper/ arco/

Status ResultFolder::WriteMethod(const MethodRecord& r) const {
  Json files = {{"points3d", kPoints3dFile}, {"hand_params", kHandParamsFile}};
  if (!r.contacts.empty()) {
    files["contact"] = kContactsCsvFile;
    files["fingering"] = kFingeringCsvFile;
  }
  const KeypointLayout* layout = FindKeypointLayout(r.layout);
  auto write = [&](const std::string& dir) -> Status {
    ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(dir, kPoints3dFile), r.points3d));
    ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(dir, kHandParamsFile), HandParams(r.hands)));
    if (!r.contacts.empty()) {
      ARCO_RETURN_IF_ERROR(WriteContactsCsv(JoinPath(dir, kContactsCsvFile), r.contacts));
      ARCO_RETURN_IF_ERROR(WriteFingeringCsv(JoinPath(dir, kFingeringCsvFile), r.fingering));
    }
    return Status::Ok();
  };
  return WriteStageFolder(r.method,
                          write,
                          {{"files", files},
                           {"layout", r.layout},
                           {"keypoint_names", layout ? layout->names : std::vector<std::string>()},
                           {"units", "mm"},
                           {"options", refine::ToJson(r.options)},
                           {"summary", refine::ToJson(r.summary)}});
}

// ---- encodings

NpyArray<double> HandParams(const std::vector<std::optional<hand::HandPose>>& hands) {
  NpyArray<double> out;
  const int64_t n = static_cast<int64_t>(hands.size());
  out.shape = {n, kHandParamsColumns};
  out.data.assign(static_cast<size_t>(n * kHandParamsColumns), kNaN);
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
  if (params.shape.size() != 2 || params.shape[1] != kHandParamsColumns) {
    return Status::Error(source + ": hand parameters must have shape (frames, 26)");
  }
  std::vector<std::optional<hand::HandPose>> out(static_cast<size_t>(params.shape[0]));
  for (int64_t f = 0; f < params.shape[0]; ++f) {
    bool finite = true;
    for (int i = 0; i < kHandParamsColumns; ++i) finite = finite && std::isfinite(params.at(f, i));
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

StatusOr<std::vector<ContactRow>> ReadContactsCsv(const std::string& path) {
  ARCO_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line)) return Status::Error(path + ": empty contact file");
  const std::vector<std::string> header = SplitCsv(line);
  std::map<std::string, size_t> col;
  for (size_t i = 0; i < header.size(); ++i) col[header[i]] = i;
  for (const char* need :
       {"frame", "string", "finger", "contact_x_mm", "contact_y_mm", "contact_z_mm"}) {
    if (!col.count(need)) {
      return Status::Error(path + ": no column '" + need + "' (expected a header like '" +
                           std::string(kContactsCsvHeader) + "')");
    }
  }
  std::vector<ContactRow> rows;
  int line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.empty()) continue;
    const std::vector<std::string> cells = SplitCsv(line);
    const std::string where = path + ":" + std::to_string(line_number) + ": ";
    if (cells.size() < header.size()) {
      return Status::Error(where + "expected " + std::to_string(header.size()) + " fields, found " +
                           std::to_string(cells.size()));
    }
    auto cell = [&](const char* name) -> const std::string* {
      const auto it = col.find(name);
      return it == col.end() ? nullptr : &cells[it->second];
    };
    bool ok = true;
    auto integer = [&](const char* name, int64_t fallback) {
      const std::string* c = cell(name);
      int64_t v = fallback;
      if (c && !ParseInt(*c, &v)) ok = false;
      return v;
    };
    auto number = [&](const char* name, double fallback) {
      const std::string* c = cell(name);
      double v = fallback;
      if (c && !ParseDouble(*c, &v)) ok = false;
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

}  // namespace arco::pipeline
