#include "arco/pipeline/result_folder.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iterator>
#include <map>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "arco/audio/double_stops_csv.h"
#include "arco/hand/hand_params.h"
#include "arco/refine/contacts_csv.h"
#include "arco/util/csv.h"
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
constexpr char kDepthSourceFile[] = "depth_source.npy";   // one camera only
constexpr char kDepthSigmaFile[] = "depth_sigma_mm.npy";  // one camera only
constexpr char kStringsFile[] = "strings.npy";
constexpr char kKeypointsFile[] = "keypoints.npy";
constexpr char kHandParamsFile[] = "hand_params.npy";
constexpr char kBoneLengthsFile[] = "bone_lengths_mm.npy";
constexpr char kRestPointsFile[] = "rest_points_mm.npy";
constexpr char kPitchCsvFile[] = "pitch.csv";
constexpr char kNotesCsvFile[] = "notes.csv";
constexpr char kDoubleStopsCsvFile[] = "double_stops.csv";
constexpr char kContactsCsvFile[] = "contacts.csv";
constexpr char kSecondContactsCsvFile[] = "contacts_2.csv";  // double stops' upper notes
constexpr char kFingeringCsvFile[] = "fingering.csv";
constexpr char kSecondFingeringCsvFile[] = "fingering_2.csv";  // double stops' upper notes
constexpr char kBowingCsvFile[] = "bowing.csv";
constexpr char kBowingNotesCsvFile[] = "bowing_notes.csv";

Status WriteFingeringCsv(const std::string& path, const std::vector<refine::NoteFingering>& rows) {
  return AtomicWriteWith(path, [&](std::ostream& out) {
    out << kFingeringCsvHeader << '\n';
    for (const refine::NoteFingering& r : rows) {
      out << r.note << ',' << r.first_frame << ',' << r.last_frame << ','
          << FormatCsvDouble(r.onset_s) << ',' << FormatCsvDouble(r.duration_s) << ','
          << FormatCsvDouble(r.f0_hz) << ',' << r.midi_note << ','
          << refine::MidiNoteName(r.midi_note) << ',' << FormatCsvDouble(r.cents_off) << ','
          << r.state << ',' << r.string << ',' << r.finger << ','
          << FormatCsvDouble(r.position_semitones) << ',' << FormatCsvDouble(r.from_nut_mm) << ','
          << r.pressed_frames << ',' << r.open_frames << ',' << r.uncertain_frames << '\n';
    }
    return Status::Ok();
  });
}

Status Expect(bool ok, const std::string& path, const std::string& what) {
  return ok ? Status::Ok() : Status::Error(path + ": " + what);
}

// result.json keys of the ties to the capture (docs/formats.md).
constexpr char kInputsKey[] = "inputs";
constexpr char kRemovedStagesKey[] = "removed_stages";

Json InputsToJson(const CaptureInputs& inputs) {
  Json j = Json::object();
  for (const auto& [role, input] : inputs) {
    j[role] = {{"file", input.file},
               {"size_bytes", input.fingerprint.size_bytes},
               {"murmur3", input.fingerprint.murmur3}};
  }
  return j;
}

// "inputs" of result.json (`field`: "inputs" or "stages.<stage>.inputs"); errors name
// the manifest and the field.
StatusOr<CaptureInputs> InputsFromJson(const Json& j,
                                       const std::string& manifest_path,
                                       const std::string& field) {
  auto bad = [&](const std::string& what) {
    return Status::Error(manifest_path + ": \"" + field + "\" " + what);
  };
  if (!j.is_object()) return bad("is not an object");
  CaptureInputs out;
  for (auto it = j.begin(); it != j.end(); ++it) {
    const Json& e = it.value();
    const std::string where = "entry '" + it.key() + "' ";
    if (!e.is_object() || !e.contains("file") || !e["file"].is_string() ||
        e["file"].get<std::string>().empty()) {
      return bad(where + "has no \"file\"");
    }
    if (!e.contains("size_bytes") || !e["size_bytes"].is_number_integer() ||
        e["size_bytes"].get<int64_t>() < 0) {
      return bad(where + "has no \"size_bytes\" (an integer >= 0)");
    }
    if (!e.contains("murmur3") || !e["murmur3"].is_string()) {
      return bad(where + "has no \"murmur3\" (a string)");
    }
    out[it.key()] = {e["file"].get<std::string>(),
                     {e["size_bytes"].get<int64_t>(), e["murmur3"].get<std::string>()}};
  }
  return out;
}

// The capture folder result.json names, resolved against the result folder ("" when
// absent).
std::string CaptureDirOf(const Json& manifest, const std::string& result_dir) {
  if (!manifest.contains("capture") || !manifest["capture"].is_string()) return "";
  const std::string capture = manifest["capture"].get<std::string>();
  if (capture.empty()) return "";
  // Relative to the result folder (absolute stays absolute).
  return NormalizeOutputPath(ResolveCapturePath(result_dir, capture));
}

// Where a stage stands in kStageOrder (the method folders after all of it).
int StageRank(const std::string& stage) {
  for (size_t i = 0; i < std::size(kStageOrder); ++i) {
    if (stage == kStageOrder[i]) return static_cast<int>(i);
  }
  return static_cast<int>(std::size(kStageOrder));
}

// A file or folder name inside the result folder, never a path that leaves it: a stage
// entry's "dir" and "files" decide what is removed.
bool PlainName(const std::string& name) {
  return !name.empty() && name != "." && name != ".." && name.find('/') == std::string::npos;
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

std::string ResultFolder::FingeringPath(const std::string& method) const {
  return StagePath(method, kFingeringCsvFile);
}

StatusOr<std::vector<refine::BowingNote>> ResultFolder::ReadBowingNotes(
    const std::string& method) const {
  const std::string path = StagePath(method, kBowingNotesCsvFile);
  if (!FileExists(path)) return std::vector<refine::BowingNote>();
  return refine::ReadBowingNotesCsv(path);
}

StatusOr<std::vector<refine::NoteFingering>> ResultFolder::ReadFingering(
    const std::string& method) const {
  return ReadFingeringCsv(FingeringPath(method));
}

StatusOr<std::vector<refine::NoteFingering>> ResultFolder::ReadSecondFingering(
    const std::string& method) const {
  return ReadFingeringCsv(StagePath(method, kSecondFingeringCsvFile));
}

StatusOr<std::vector<refine::NoteFingering>> ReadFingeringCsv(const std::string& path) {
  std::vector<refine::NoteFingering> rows;
  if (!FileExists(path)) return rows;
  std::vector<std::string> required;
  // note_name is derived from midi_note; every other column is read.
  for (const std::string& w : SplitCsvLine(kFingeringCsvHeader))
    if (w != "note_name") required.push_back(w);
  ARCO_ASSIGN_OR_RETURN(const CsvTable table, ReadCsvTable(path, required, kFingeringCsvHeader));
  for (const CsvTable::Row& row : table.rows) {
    const std::vector<std::string>& cells = row.cells;
    const std::string where = table.Where(row);
    auto cell = [&](const char* name) -> const std::string* {
      const int c = table.Column(name);
      return c < 0 ? nullptr : &cells[c];
    };
    bool ok = true;
    auto integer = [&](const char* name, auto* out) {
      const std::string* c = cell(name);
      int64_t v = 0;
      if (c == nullptr || !ParseCsvInt(*c, &v)) {
        ok = false;
        return;
      }
      *out = static_cast<std::remove_pointer_t<decltype(out)>>(v);
    };
    auto number = [&](const char* name, double* out) {
      const std::string* c = cell(name);
      if (c == nullptr || !ParseCsvDouble(*c, out)) ok = false;
    };
    refine::NoteFingering r;
    integer("note", &r.note);
    integer("first_frame", &r.first_frame);
    integer("last_frame", &r.last_frame);
    number("onset_s", &r.onset_s);
    number("duration_s", &r.duration_s);
    number("f0_hz", &r.f0_hz);
    integer("midi_note", &r.midi_note);
    number("cents_off", &r.cents_off);
    const std::string* state = cell("state");
    if (state == nullptr)
      ok = false;
    else
      r.state = *state;
    integer("string", &r.string);
    integer("finger", &r.finger);
    number("position_semitones", &r.position_semitones);
    number("from_nut_mm", &r.from_nut_mm);
    integer("pressed_frames", &r.pressed_frames);
    integer("open_frames", &r.open_frames);
    integer("uncertain_frames", &r.uncertain_frames);
    if (!ok) return Status::Error(where + "a cell that is not a number");
    if (r.last_frame < r.first_frame) {
      return Status::Error(where + "last_frame is before first_frame");
    }
    rows.push_back(std::move(r));
  }
  return rows;
}

ResultFolder ResultFolder::Exclusive(std::string dir) {
  ResultFolder folder(std::move(dir));
  folder.held_ = std::make_shared<HeldManifest>();
  return folder;
}

StatusOr<Json> ResultFolder::ReadManifest() const {
  if (held_ && held_->manifest) return *held_->manifest;
  const std::string path = ManifestPath();
  Json j = Json::object();
  if (FileExists(path)) {
    ARCO_ASSIGN_OR_RETURN(j, ReadJsonFile(path));
    if (!j.is_object() || j.value("format", "") != "arco-result") {
      return Status::Error(path + ": not an arco result manifest (\"format\": \"arco-result\")");
    }
  }
  if (held_) held_->manifest = j;
  return j;
}

void ResultFolder::RequireDir(const std::string& result_dir) const {
  if (result_dir != dir_) {
    throw std::invalid_argument("result folder " + dir_ + " given with result_dir " + result_dir);
  }
}

void ResultFolder::Committed(const Json& manifest) const {
  if (held_) held_->manifest = manifest;
}

StatusOr<ResultHeader> ResultFolder::ReadHeader(InputCheck check) const {
  if (check == InputCheck::kCompare) ARCO_RETURN_IF_ERROR(CheckInputs());
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
  h.capture_dir = CaptureDirOf(result, dir_);
  return h;
}

namespace {

// One capture file result.json records, with the path it names now.
struct RecordedInput {
  std::string role;
  std::string path;
  Fingerprint fingerprint;
};

// Every input of result.json "inputs" and of each stage's "inputs".
StatusOr<std::vector<RecordedInput>> RecordedInputs(const Json& manifest,
                                                    const std::string& result_dir,
                                                    const std::string& manifest_path) {
  std::vector<std::pair<std::string, const Json*>> lists;
  if (manifest.contains(kInputsKey)) lists.push_back({kInputsKey, &manifest[kInputsKey]});
  if (manifest.contains("stages") && manifest["stages"].is_object()) {
    for (auto it = manifest["stages"].begin(); it != manifest["stages"].end(); ++it) {
      if (it.value().is_object() && it.value().contains(kInputsKey)) {
        lists.push_back({"stages." + it.key() + "." + kInputsKey, &it.value()[kInputsKey]});
      }
    }
  }
  std::vector<RecordedInput> out;
  if (lists.empty()) return out;  // a result of an older arco: nothing recorded
  const std::string capture_dir = CaptureDirOf(manifest, result_dir);
  if (capture_dir.empty()) {
    return Status::Error(manifest_path + ": \"inputs\" recorded but no \"capture\" folder");
  }
  for (const auto& [field, list] : lists) {
    ARCO_ASSIGN_OR_RETURN(const CaptureInputs inputs, InputsFromJson(*list, manifest_path, field));
    for (const auto& [role, input] : inputs) {
      out.push_back({role, ResolveCapturePath(capture_dir, input.file), input.fingerprint});
    }
  }
  // The manifest first: a replaced capture is named by its capture.json.
  std::stable_partition(
      out.begin(), out.end(), [](const RecordedInput& r) { return r.role == kManifestInput; });
  return out;
}

}  // namespace

Status ResultFolder::CheckInputs() const {
  ARCO_ASSIGN_OR_RETURN(const Json manifest, ReadManifest());
  ARCO_ASSIGN_OR_RETURN(const std::vector<RecordedInput> recorded,
                        RecordedInputs(manifest, dir_, ManifestPath()));
  std::map<std::string, Fingerprint> now;  // each file hashed once
  for (const RecordedInput& r : recorded) {
    auto it = now.find(r.path);
    if (it == now.end()) {
      if (!FileExists(r.path)) {
        return Status::Error(r.path + " changed since the result " + dir_ +
                             " was made (it is gone; re-run `arco run`)");
      }
      ARCO_ASSIGN_OR_RETURN(Fingerprint f, FingerprintFile(r.path));
      it = now.emplace(r.path, std::move(f)).first;
    }
    if (it->second != r.fingerprint) {
      return Status::Error(r.path + " changed since the result " + dir_ +
                           " was made (re-run `arco run`)");
    }
  }
  return Status::Ok();
}

Status ResultFolder::CheckInputsMatch(const CaptureInputs& capture) const {
  ARCO_ASSIGN_OR_RETURN(const Json manifest, ReadManifest());
  ARCO_ASSIGN_OR_RETURN(const std::vector<RecordedInput> recorded,
                        RecordedInputs(manifest, dir_, ManifestPath()));
  for (const RecordedInput& r : recorded) {
    auto it = capture.find(r.role);
    if (it != capture.end() && it->second.fingerprint != r.fingerprint) {
      return Status::Error(r.path + " changed since the result " + dir_ +
                           " was made (re-run `arco run`)");
    }
  }
  return Status::Ok();
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
    if (sj["files"].contains("contact_2"))
      s.second_contacts_path = JoinPath(dir, sj["files"]["contact_2"].get<std::string>());
    if (sj["files"].contains("bowing"))
      s.bowing_path = JoinPath(dir, sj["files"]["bowing"].get<std::string>());
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

StatusOr<std::vector<std::string>> ResultFolder::RemoveLaterStages(const std::string& stage,
                                                                   OutputSet* outputs,
                                                                   Json* manifest) const {
  std::vector<std::string> removed;
  if (!manifest->contains("stages") || !(*manifest)["stages"].is_object()) return removed;
  Json& stages = (*manifest)["stages"];
  for (auto it = stages.begin(); it != stages.end(); ++it) {
    if (StageRank(it.key()) <= StageRank(stage)) continue;
    const Json& e = it.value();
    const std::string dir = e.is_object() && e.contains("dir") && e["dir"].is_string()
                                ? e["dir"].get<std::string>()
                                : it.key();
    std::vector<std::string> names;
    if (dir == ".") {  // files in the folder itself (pitch.csv, notes.csv)
      if (e.is_object() && e.contains("files") && e["files"].is_object()) {
        for (const Json& f : e["files"]) {
          if (f.is_string()) names.push_back(f.get<std::string>());
        }
      }
    } else {
      names.push_back(dir);
    }
    for (const std::string& name : names) {
      if (!PlainName(name)) {
        return Status::Error(ManifestPath() + ": stage '" + it.key() + "' names '" + name +
                             "': not a name inside the result folder");
      }
      ARCO_RETURN_IF_ERROR(outputs->AddRemoval(JoinPath(dir_, name)));
    }
    removed.push_back(it.key());
  }
  // In the order of the stages (the manifest's keys are alphabetical).
  std::stable_sort(removed.begin(), removed.end(), [](const std::string& a, const std::string& b) {
    return StageRank(a) < StageRank(b);
  });
  for (const std::string& name : removed) stages.erase(name);
  if (!removed.empty()) {
    Json& names = (*manifest)[kRemovedStagesKey];
    if (!names.is_array()) names = Json::array();
    for (const std::string& name : removed) {
      if (std::find(names.begin(), names.end(), Json(name)) == names.end()) names.push_back(name);
    }
  }
  return removed;
}

namespace {

// `manifest` with `stage` written from `inputs`: its entry's "inputs", merged into the
// result's, and its name no longer among "removed_stages".
void RecordStageInputs(Json* manifest, const std::string& stage, const CaptureInputs& inputs) {
  const Json recorded = InputsToJson(inputs);
  (*manifest)["stages"][stage][kInputsKey] = recorded;
  Json& all = (*manifest)[kInputsKey];
  if (!all.is_object()) all = Json::object();
  for (auto it = recorded.begin(); it != recorded.end(); ++it) all[it.key()] = it.value();
  if (manifest->contains(kRemovedStagesKey) && (*manifest)[kRemovedStagesKey].is_array()) {
    Json& names = (*manifest)[kRemovedStagesKey];
    names.erase(std::remove(names.begin(), names.end(), Json(stage)), names.end());
    if (names.empty()) manifest->erase(kRemovedStagesKey);
  }
}

}  // namespace

Status ResultFolder::WriteStageFolder(const std::string& stage,
                                      const std::function<Status(const std::string& dir)>& write,
                                      Json entry,
                                      const CaptureInputs& inputs) const {
  ARCO_ASSIGN_OR_RETURN(Json manifest, ReadManifest());  // not some other JSON
  ARCO_RETURN_IF_ERROR(MakeDirectories(dir_));
  // The folder, result.json and the removal of the later stages happen together or not
  // at all.
  OutputSet outputs;
  ARCO_ASSIGN_OR_RETURN(const std::string tmp_dir,
                        outputs.AddFolder(JoinPath(dir_, stage), OwnStageFolder()));
  ARCO_ASSIGN_OR_RETURN(const std::string tmp_manifest, outputs.AddFile(ManifestPath()));
  ARCO_RETURN_IF_ERROR(RemoveLaterStages(stage, &outputs, &manifest).status());
  ARCO_RETURN_IF_ERROR(write(tmp_dir));
  entry["dir"] = stage;
  manifest = WithStage(manifest, stage, entry);
  RecordStageInputs(&manifest, stage, inputs);
  ARCO_RETURN_IF_ERROR(WriteJsonFile(tmp_manifest, manifest));
  ARCO_RETURN_IF_ERROR(outputs.Commit());
  Committed(manifest);
  return Status::Ok();
}

Status ResultFolder::WriteRunOptions(const Json& options) const {
  ARCO_ASSIGN_OR_RETURN(Json manifest, ReadManifest());
  manifest["options"] = options;
  OutputSet outputs;
  ARCO_ASSIGN_OR_RETURN(const std::string tmp_manifest, outputs.AddFile(ManifestPath()));
  ARCO_RETURN_IF_ERROR(WriteJsonFile(tmp_manifest, manifest));
  ARCO_RETURN_IF_ERROR(outputs.Commit());
  Committed(manifest);
  return Status::Ok();
}

// ---- triangulation/

StatusOr<std::vector<std::string>> ResultFolder::WriteTriangulation(
    const CaptureManifest& manifest,
    const KeypointLayout& layout,
    const SequenceTriangulation& raw,
    const NpyArray<double>& points3d_filtered,
    const TriangulationRecord& record) const {
  ARCO_ASSIGN_OR_RETURN(Json result, ReadManifest());
  ARCO_RETURN_IF_ERROR(MakeDirectories(dir_));
  // triangulation/, result.json and the removal of the later stages happen together or
  // not at all.
  OutputSet outputs;
  ARCO_ASSIGN_OR_RETURN(const std::string stage_tmp,
                        outputs.AddFolder(JoinPath(dir_, kTriangulationStage), OwnStageFolder()));
  ARCO_ASSIGN_OR_RETURN(const std::string manifest_tmp, outputs.AddFile(ManifestPath()));
  ARCO_ASSIGN_OR_RETURN(const std::vector<std::string> removed,
                        RemoveLaterStages(kTriangulationStage, &outputs, &result));
  auto write_all = [&](const std::string& tmp_dir) -> Status {
    ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(tmp_dir, kPoints3dFile), points3d_filtered));
    ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(tmp_dir, kPoints3dRawFile), raw.points3d));
    ARCO_RETURN_IF_ERROR(
        WriteNpy(JoinPath(tmp_dir, kReprojectionRmsFile), raw.rms_reprojection_px));
    ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(tmp_dir, kInlierCountFile), raw.num_inliers));
    ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(tmp_dir, kViewCountFile), raw.num_views));
    ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(tmp_dir, kInlierMaskFile), raw.inlier_mask));
    if (!raw.depth_source.data.empty())
      ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(tmp_dir, kDepthSourceFile), raw.depth_source));
    if (!raw.depth_sigma_mm.data.empty())
      ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(tmp_dir, kDepthSigmaFile), raw.depth_sigma_mm));
    return Status::Ok();
  };
  ARCO_RETURN_IF_ERROR(write_all(stage_tmp));

  result["format"] = "arco-result";
  result["version"] = 1;
  // Relative to the result folder (docs/formats.md), so that the two can move together
  // (absolute when given so); dir_ may be a temporary sibling of the final folder: the
  // same parent, the same relative path.
  result["capture"] = PathRelativeTo(record.capture_dir, dir_);
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
  if (!raw.depth_source.data.empty()) {
    // One camera: the depths are not measured (track/monocular_lift.h LiftDepth).
    Json& stage = result["stages"][kTriangulationStage];
    stage["files"]["depth_source"] = kDepthSourceFile;
    if (!raw.depth_sigma_mm.data.empty()) stage["files"]["depth_sigma_mm"] = kDepthSigmaFile;
    stage["depth"] = {
        {"method", "one_view"},
        {"codes",
         {{"0", "not lifted"},
          {"1", "instrument pose (PnP of its nominal points)"},
          {"2", "the depth where the fingertips pass closest to the strings (left hand)"},
          {"3", "assumed plane behind the instrument (body, right hand)"}}}};
    if (record.one_view_camera_centre) {
      Json centre = Json::array();
      for (int c = 0; c < 3; ++c) centre.push_back((*record.one_view_camera_centre)[c]);
      stage["depth"]["camera_centre_in_world"] = centre;
    }
  }
  // A new capture header: the result is now what this triangulation was made from, and
  // `arco run`'s options no longer describe it.
  result.erase(kInputsKey);
  result.erase("options");
  RecordStageInputs(&result, kTriangulationStage, record.inputs);
  ARCO_RETURN_IF_ERROR(WriteJsonFile(manifest_tmp, result));
  ARCO_RETURN_IF_ERROR(outputs.Commit());
  Committed(result);
  return removed;
}

StatusOr<NpyArray<double>> ResultFolder::ReadPoints3d(const std::string& stage) const {
  return ReadNpy<double>(Points3dPath(stage));
}

StatusOr<ResultFolder::TriangulationQuality> ResultFolder::ReadTriangulationQuality() const {
  TriangulationQuality q;
  ARCO_ASSIGN_OR_RETURN(q.rms_reprojection_px,
                        ReadNpy<float>(StagePath(kTriangulationStage, kReprojectionRmsFile)));
  ARCO_ASSIGN_OR_RETURN(q.num_inliers,
                        ReadNpy<int32_t>(StagePath(kTriangulationStage, kInlierCountFile)));
  return q;
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
      entry,
      r.inputs);
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
  NpyArray<double> rest;
  rest.shape = {hand::kNumHandKeypoints, 3};
  for (const Eigen::Vector3d& p : r.rest_points_mm)
    rest.data.insert(rest.data.end(), {p.x(), p.y(), p.z()});
  Json entry = {{"files",
                 {{"hand_params", kHandParamsFile},
                  {"bone_lengths_mm", kBoneLengthsFile},
                  {"rest_points_mm", kRestPointsFile}}},
                {"side", "left"},
                {"units", "mm"},
                {"summary", ToJson(r.summary)}};
  return WriteStageFolder(
      kHandStage,
      [&](const std::string& dir) -> Status {
        ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(dir, kHandParamsFile), hand::HandParams(r.hands)));
        ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(dir, kBoneLengthsFile), lengths));
        return WriteNpy(JoinPath(dir, kRestPointsFile), rest);
      },
      entry,
      r.inputs);
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
  ARCO_ASSIGN_OR_RETURN(r.hands, hand::HandsFromParams(params, hands_path));
  for (int k = 0; k < hand::kNumHandKeypoints; ++k)
    r.bone_lengths_mm[static_cast<size_t>(k)] = bones.data[static_cast<size_t>(k)];
  const hand::HandModel left = hand::HandModel::Default(hand::HandSide::kLeft);
  const std::string rest_path = StagePath(kHandStage, kRestPointsFile);
  if (!FileExists(rest_path)) {  // results of versions before the performer's palm
    StatusOr<hand::HandModel> sized = left.WithBoneLengths(r.bone_lengths_mm);
    if (!sized.ok()) return sized.status().WithContext(bones_path);
    r.rest_points_mm = sized->rest_points_mm();
    return r;
  }
  ARCO_ASSIGN_OR_RETURN(NpyArray<double> rest, ReadNpy<double>(rest_path));
  ARCO_RETURN_IF_ERROR(Expect(rest.shape == std::vector<int64_t>{hand::kNumHandKeypoints, 3},
                              rest_path,
                              "expected (21, 3) rest points"));
  for (int k = 0; k < hand::kNumHandKeypoints; ++k) {
    for (int c = 0; c < 3; ++c) r.rest_points_mm[static_cast<size_t>(k)][c] = rest.at(k, c);
  }
  StatusOr<hand::HandModel> model = left.WithRestPoints(r.rest_points_mm);
  if (!model.ok()) return model.status().WithContext(rest_path);
  return r;
}

// ---- pitch.csv, notes.csv

Status ResultFolder::WritePitch(const PitchRecord& r) const {
  ARCO_ASSIGN_OR_RETURN(Json manifest, ReadManifest());
  ARCO_RETURN_IF_ERROR(MakeDirectories(dir_));
  // pitch.csv, notes.csv, double_stops.csv and result.json change together or not at all.
  OutputSet outputs;
  ARCO_ASSIGN_OR_RETURN(const std::string pitch_tmp, outputs.AddFile(PitchPath()));
  ARCO_ASSIGN_OR_RETURN(const std::string notes_tmp,
                        outputs.AddFile(JoinPath(dir_, kNotesCsvFile)));
  const std::string double_stops_path = JoinPath(dir_, kDoubleStopsCsvFile);
  std::string double_stops_tmp;
  if (!r.double_stops.empty()) {
    ARCO_ASSIGN_OR_RETURN(double_stops_tmp, outputs.AddFile(double_stops_path));
  } else {
    ARCO_RETURN_IF_ERROR(outputs.AddRemoval(double_stops_path));  // an earlier run's
  }
  ARCO_ASSIGN_OR_RETURN(const std::string manifest_tmp, outputs.AddFile(ManifestPath()));
  ARCO_RETURN_IF_ERROR(RemoveLaterStages(kPitchStage, &outputs, &manifest).status());
  ARCO_RETURN_IF_ERROR(audio::WritePitchCsv(pitch_tmp, r.frames));
  ARCO_RETURN_IF_ERROR(audio::WriteNotesCsv(notes_tmp, r.notes));
  Json entry = {{"dir", "."},
                {"files", {{"pitch", kPitchCsvFile}, {"notes", kNotesCsvFile}}},
                {"a4_hz", r.a4_hz},
                {"audio", r.summary.audio},
                {"summary", ToJson(r.summary)}};
  if (!r.double_stops.empty()) {
    ARCO_RETURN_IF_ERROR(
        AtomicWriteFile(double_stops_tmp, audio::FormatDoubleStopsCsv(r.double_stops)));
    int64_t two = 0;
    for (const audio::PolyPitchFrame& f : r.double_stops) two += f.count == 2;
    entry["files"]["double_stops"] = kDoubleStopsCsvFile;
    entry["double_stops"] = {{"frames_with_two_notes", two}};
  }
  manifest = WithStage(manifest, kPitchStage, entry);
  RecordStageInputs(&manifest, kPitchStage, r.inputs);
  ARCO_RETURN_IF_ERROR(WriteJsonFile(manifest_tmp, manifest));
  ARCO_RETURN_IF_ERROR(outputs.Commit());
  Committed(manifest);
  return Status::Ok();
}

std::string ResultFolder::PitchPath() const { return JoinPath(dir_, kPitchCsvFile); }

StatusOr<std::vector<audio::PitchFrame>> ResultFolder::ReadPitch() const {
  return audio::ReadPitchCsv(PitchPath());
}

StatusOr<std::vector<audio::PolyPitchFrame>> ResultFolder::ReadDoubleStops() const {
  const std::string path = JoinPath(dir_, kDoubleStopsCsvFile);
  if (!FileExists(path)) return std::vector<audio::PolyPitchFrame>();
  return audio::ReadDoubleStopsCsv(path);
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
  if (!r.second_contacts.empty()) files["contact_2"] = kSecondContactsCsvFile;
  if (!r.second_fingering.empty()) files["fingering_2"] = kSecondFingeringCsvFile;
  if (r.bowing) {
    files["bowing"] = kBowingCsvFile;
    files["bowing_notes"] = kBowingNotesCsvFile;
  }
  const KeypointLayout* layout = FindKeypointLayout(r.layout);
  auto write = [&](const std::string& dir) -> Status {
    ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(dir, kPoints3dFile), r.points3d));
    ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(dir, kHandParamsFile), hand::HandParams(r.hands)));
    if (!r.contacts.empty()) {
      ARCO_RETURN_IF_ERROR(refine::WriteContactsCsv(JoinPath(dir, kContactsCsvFile), r.contacts));
      ARCO_RETURN_IF_ERROR(WriteFingeringCsv(JoinPath(dir, kFingeringCsvFile), r.fingering));
    }
    if (!r.second_contacts.empty()) {
      ARCO_RETURN_IF_ERROR(
          refine::WriteContactsCsv(JoinPath(dir, kSecondContactsCsvFile), r.second_contacts));
    }
    if (!r.second_fingering.empty()) {
      ARCO_RETURN_IF_ERROR(
          WriteFingeringCsv(JoinPath(dir, kSecondFingeringCsvFile), r.second_fingering));
    }
    if (r.bowing) {
      ARCO_RETURN_IF_ERROR(refine::WriteBowingCsv(JoinPath(dir, kBowingCsvFile), r.bowing->frames));
      ARCO_RETURN_IF_ERROR(
          refine::WriteBowingNotesCsv(JoinPath(dir, kBowingNotesCsvFile), r.bowing->notes));
    }
    return Status::Ok();
  };
  Json entry = {{"files", files},
                {"layout", r.layout},
                {"keypoint_names", layout ? layout->names : std::vector<std::string>()},
                {"units", "mm"},
                {"options", refine::ToJson(r.options)},
                {"summary", refine::ToJson(r.summary)}};
  if (!r.second_contacts.empty()) {
    const refine::DoubleStopRefineOptions& o = r.double_stop_options;
    const refine::DoubleStopRefineSummary& d = r.double_stop_summary;
    entry["double_stops"] = {{"options",
                              {{"open_tolerance_cents", o.open_tolerance_cents},
                               {"max_span_semitones", o.max_span_semitones},
                               {"fifth_semitones", o.fifth_semitones},
                               {"max_tip_distance_mm", o.max_tip_distance_mm},
                               {"max_iterations", o.max_iterations},
                               {"fill_notes", o.fill_notes},
                               {"tie_chords", o.tie_chords},
                               {"chord_gap_s", o.chord_gap_s},
                               {"chord_lower_max_s", o.chord_lower_max_s},
                               {"attack_s", o.attack_s},
                               {"bow_gate", o.bow_gate},
                               {"bow_octaves", o.bow_octaves},
                               {"bow_pairs", o.bow_pairs}}},
                             {"summary",
                              {{"frames", d.frames},
                               {"bow_one_string", d.bow_one_string},
                               {"bow_octaves", d.bow_octaves},
                               {"attack_frames", d.attack_frames},
                               {"bow_pairs", d.bow_pairs},
                               {"pressed", d.pressed},
                               {"open_string", d.open_string},
                               {"one_finger_fifths", d.one_finger_fifths},
                               {"first_fingers_changed", d.first_fingers_changed},
                               {"chord_frames_moved", d.chord_frames_moved},
                               {"uncertain", d.uncertain},
                               {"joint_limit_violations", d.joint_limit_violations}}}};
  }
  if (r.bowing) {
    entry["bowing"] = {{"options", refine::ToJson(r.bowing_options)},
                       {"summary", refine::ToJson(r.bowing->summary)}};
  }
  return WriteStageFolder(r.method,
                          write,
                          entry,
                          // The methods read the earlier stages, not the capture: those
                          // stages' inputs are the method's too.
                          CaptureInputs());
}

}  // namespace arco::pipeline
