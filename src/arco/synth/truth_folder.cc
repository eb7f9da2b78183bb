#include "arco/synth/truth_folder.h"

#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "arco/hand/hand_params.h"
#include "arco/synth/score.h"
#include "arco/util/csv.h"
#include "arco/util/file_io.h"
#include "arco/util/json_io.h"

namespace arco::synth {
namespace {

constexpr char kTruthFormat[] = "arco-synth-truth";
constexpr int kTruthVersion = 1;
constexpr char kManifestFile[] = "truth.json";
constexpr char kPoints3dFile[] = "points3d.npy";
constexpr char kLeftHandPoseFile[] = "left_hand_pose.npy";
constexpr char kRightHandPoseFile[] = "right_hand_pose.npy";
constexpr char kInstrumentPoseFile[] = "instrument_pose.npy";
constexpr char kContactFile[] = "contact.csv";
constexpr char kSecondContactFile[] = "contact_2.csv";  // double stops' upper notes
constexpr char kSecondNotesFile[] = "notes_2.csv";
constexpr char kPitchFile[] = "pitch.csv";
constexpr char kNotesFile[] = "notes.csv";
constexpr char kBowingFile[] = "bowing.csv";  // refine/bowing.h's format
constexpr char kContactCsvHeader[] =
    "frame,time_s,state,string,finger,note,f0_hz,contact_x_mm,contact_y_mm,contact_z_mm";
constexpr char kNotesCsvHeader[] =
    "note,onset_s,offset_s,midi_note,name,velocity,string,finger,position_semitones,"
    "intonation_cents,vibrato_rate_hz,vibrato_extent_cents";

Json ManifestJson(const TruthManifest& m, bool has_bowing, bool has_double_stops) {
  Json j;
  j["format"] = kTruthFormat;
  j["version"] = kTruthVersion;
  j["instrument"] = m.instrument;
  j["piece"] = m.piece;
  j["seed"] = m.seed;
  j["fps"] = m.fps;
  j["frames"] = m.frames;
  j["notes"] = m.notes;
  j["pressed_frames"] = m.pressed_frames;
  j["max_residual_shift_mm"] = m.max_residual_shift_mm;
  j["layout"] = m.layout;
  j["truth_layout"] = m.truth_layout;
  j["units"] = m.units;
  j["calibration_source"] = m.calibration_source;
  j["stage"] = {{"mm_per_unit", m.mm_per_unit},
                {"median_camera_distance_mm", m.median_camera_distance_mm},
                {"performer_origin_in_world_mm",
                 {m.performer_origin_in_world_mm.x(),
                  m.performer_origin_in_world_mm.y(),
                  m.performer_origin_in_world_mm.z()}}};
  j["hand_model"] = m.hand_model;
  j["detection"] = {{"noise_px", m.noise_px},
                    {"outlier_rate", m.outlier_rate},
                    {"occlusion_rate", m.occlusion_rate},
                    {"finger_bias_mm", m.finger_bias_mm}};
  j["fingering"] = {{"shifts", m.fingering_shifts},
                    {"open_strings", m.fingering_open_strings},
                    {"string_crossings", m.fingering_string_crossings},
                    {"total_cost", m.fingering_total_cost}};
  if (!m.motion_source.empty()) j["motion_source"] = m.motion_source;
  if (!m.audio_source.empty()) j["audio_source"] = m.audio_source;
  if (!m.error_model.is_null()) j["error_model"] = m.error_model;
  Json offsets = Json::object();
  for (const auto& [key, cents] : m.sample_median_offset_cents)
    offsets[std::to_string(key)] = cents;
  j["sample_median_offset_cents"] = offsets;
  j["files"] = {{"points3d", kPoints3dFile},
                {"left_hand_pose", kLeftHandPoseFile},
                {"right_hand_pose", kRightHandPoseFile},
                {"instrument_pose", kInstrumentPoseFile},
                {"contact", kContactFile},
                {"pitch", kPitchFile},
                {"notes", kNotesFile}};
  if (has_bowing) j["files"]["bowing"] = kBowingFile;
  if (has_double_stops) {
    j["double_stops"] = m.double_stops;
    j["files"]["contact_2"] = kSecondContactFile;
    j["files"]["notes_2"] = kSecondNotesFile;
  }
  return j;
}

// Reads truth.json's fields; `path` names the file in errors.
StatusOr<TruthManifest> ManifestFromJson(const Json& j, const std::string& path) {
  const auto format = j.is_object() ? j.find("format") : j.end();
  if (!j.is_object() || format == j.end() || *format != kTruthFormat) {
    return Status::Error(path + ": not a synthetic truth manifest (format \"" + kTruthFormat +
                         "\")");
  }
  bool ok = true;
  std::string bad;
  // A missing key keeps the default; a key of the wrong type is an error.
  auto get = [&](const Json& obj, const char* key, auto* out, bool required = false) {
    const auto it = obj.find(key);
    if (it == obj.end() || it->is_null()) {
      if (required && ok) ok = false, bad = std::string("no \"") + key + "\"";
      return;
    }
    try {
      *out = it->template get<std::decay_t<decltype(*out)>>();
    } catch (const Json::exception&) {
      if (ok) ok = false, bad = std::string("\"") + key + "\" has the wrong type";
    }
  };
  int version = 0;
  get(j, "version", &version, true);
  if (ok && version != kTruthVersion)
    return Status::Error(path + ": version " + std::to_string(version) + " (expected " +
                         std::to_string(kTruthVersion) + ")");
  TruthManifest m;
  get(j, "instrument", &m.instrument);
  get(j, "piece", &m.piece);
  get(j, "seed", &m.seed);
  get(j, "fps", &m.fps, true);
  get(j, "frames", &m.frames, true);
  get(j, "notes", &m.notes);
  get(j, "pressed_frames", &m.pressed_frames);
  get(j, "max_residual_shift_mm", &m.max_residual_shift_mm);
  get(j, "layout", &m.layout, true);
  get(j, "truth_layout", &m.truth_layout, true);
  get(j, "units", &m.units);
  get(j, "calibration_source", &m.calibration_source);
  get(j, "hand_model", &m.hand_model);
  get(j, "motion_source", &m.motion_source);
  get(j, "audio_source", &m.audio_source);
  get(j, "double_stops", &m.double_stops);
  if (j.contains("error_model")) m.error_model = j["error_model"];
  const Json empty = Json::object();
  const Json& stage = j.contains("stage") && j["stage"].is_object() ? j["stage"] : empty;
  get(stage, "mm_per_unit", &m.mm_per_unit);
  get(stage, "median_camera_distance_mm", &m.median_camera_distance_mm);
  std::vector<double> origin;
  get(stage, "performer_origin_in_world_mm", &origin);
  if (ok && !origin.empty()) {
    if (origin.size() != 3)
      return Status::Error(path + ": performer_origin_in_world_mm is not xyz");
    m.performer_origin_in_world_mm = Eigen::Vector3d(origin[0], origin[1], origin[2]);
  }
  const Json& detection =
      j.contains("detection") && j["detection"].is_object() ? j["detection"] : empty;
  get(detection, "noise_px", &m.noise_px);
  get(detection, "outlier_rate", &m.outlier_rate);
  get(detection, "occlusion_rate", &m.occlusion_rate);
  get(detection, "finger_bias_mm", &m.finger_bias_mm);
  const Json& fingering =
      j.contains("fingering") && j["fingering"].is_object() ? j["fingering"] : empty;
  get(fingering, "shifts", &m.fingering_shifts);
  get(fingering, "open_strings", &m.fingering_open_strings);
  get(fingering, "string_crossings", &m.fingering_string_crossings);
  get(fingering, "total_cost", &m.fingering_total_cost);
  if (j.contains("sample_median_offset_cents") && j["sample_median_offset_cents"].is_object()) {
    for (const auto& [key, cents] : j["sample_median_offset_cents"].items()) {
      int64_t midi = 0;
      if (!ParseCsvInt(key, &midi) || !cents.is_number()) {
        if (ok) ok = false, bad = "sample_median_offset_cents has an entry '" + key + "'";
        continue;
      }
      m.sample_median_offset_cents[static_cast<int>(midi)] = cents.get<double>();
    }
  }
  if (!ok) return Status::Error(path + ": " + bad);
  if (!(m.fps > 0)) return Status::Error(path + ": fps must be positive");
  if (m.frames < 0) return Status::Error(path + ": frames must not be negative");
  return m;
}

std::string ContactCsv(const std::vector<refine::ContactRow>& rows, double fps) {
  std::ostringstream out;
  out << kContactCsvHeader << '\n';
  char line[256];
  for (const refine::ContactRow& r : rows) {
    std::snprintf(line,
                  sizeof(line),
                  "%lld,%.6f,%s,%d,%d,%d,%.4f,%.4f,%.4f,%.4f\n",
                  static_cast<long long>(r.frame),
                  static_cast<double>(r.frame) / fps,
                  r.state.c_str(),
                  r.string,
                  r.finger,
                  r.note,
                  r.f0_hz,
                  r.point_mm.x(),
                  r.point_mm.y(),
                  r.point_mm.z());
    out << line;
  }
  return out.str();
}

std::string NotesCsv(const std::vector<TruthNote>& notes) {
  std::ostringstream out;
  out << kNotesCsvHeader << '\n';
  char line[256];
  for (size_t i = 0; i < notes.size(); ++i) {
    const TruthNote& n = notes[i];
    std::snprintf(line,
                  sizeof(line),
                  "%d,%.6f,%.6f,%d,%s,%d,%d,%d,%d,%.3f,%.3f,%.3f\n",
                  static_cast<int>(i),
                  n.onset_s,
                  n.offset_s,
                  n.midi_note,
                  MidiNoteName(n.midi_note).c_str(),
                  n.velocity,
                  n.string,
                  n.finger,
                  n.position_semitones,
                  n.intonation_cents,
                  n.vibrato_rate_hz,
                  n.vibrato_extent_cents);
    out << line;
  }
  return out.str();
}

StatusOr<std::vector<TruthNote>> ReadNotesCsv(const std::string& path) {
  ARCO_ASSIGN_OR_RETURN(const CsvTable table,
                        ReadCsvTable(path, SplitCsvLine(kNotesCsvHeader), kNotesCsvHeader));
  if (table.header != SplitCsvLine(kNotesCsvHeader)) {
    return Status::Error(path + ": expected the header '" + std::string(kNotesCsvHeader) + "'");
  }
  std::vector<TruthNote> notes;
  for (const CsvTable::Row& row : table.rows) {
    const std::string where = table.Where(row);
    const std::vector<std::string>& c = row.cells;
    int64_t index = 0, midi = 0, velocity = 0, string = 0, finger = 0, position = 0;
    TruthNote n;
    const bool ok =
        ParseCsvInt(c[0], &index) && ParseCsvDouble(c[1], &n.onset_s) &&
        ParseCsvDouble(c[2], &n.offset_s) && ParseCsvInt(c[3], &midi) &&
        ParseCsvInt(c[5], &velocity) && ParseCsvInt(c[6], &string) && ParseCsvInt(c[7], &finger) &&
        ParseCsvInt(c[8], &position) && ParseCsvDouble(c[9], &n.intonation_cents) &&
        ParseCsvDouble(c[10], &n.vibrato_rate_hz) && ParseCsvDouble(c[11], &n.vibrato_extent_cents);
    if (!ok) return Status::Error(where + "a field is not a number");
    if (index != static_cast<int64_t>(notes.size()))
      return Status::Error(where + "notes must be numbered 0, 1, ... in order");
    n.midi_note = static_cast<int>(midi);
    n.velocity = static_cast<int>(velocity);
    n.string = static_cast<int>(string);
    n.finger = static_cast<int>(finger);
    n.position_semitones = static_cast<int>(position);
    notes.push_back(n);
  }
  return notes;
}

}  // namespace

std::string TruthManifestPath(const std::string& dir) { return JoinPath(dir, kManifestFile); }
std::string TruthPoints3dPath(const std::string& dir) { return JoinPath(dir, kPoints3dFile); }

Status WriteTruthFolder(const std::string& dir, const TruthFolder& t) {
  ARCO_RETURN_IF_ERROR(MakeDirectories(dir));
  ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(dir, kPoints3dFile), t.points3d));
  ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(dir, kLeftHandPoseFile), hand::HandParams(t.left_hand)));
  ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(dir, kRightHandPoseFile), hand::HandParams(t.right_hand)));
  NpyArray<double> poses;
  poses.shape = {static_cast<int64_t>(t.world_from_instrument.size()), 4, 4};
  for (const Eigen::Matrix4d& p : t.world_from_instrument) {
    for (int r = 0; r < 4; ++r) {
      for (int k = 0; k < 4; ++k) poses.data.push_back(p(r, k));
    }
  }
  ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(dir, kInstrumentPoseFile), poses));
  ARCO_RETURN_IF_ERROR(
      AtomicWriteFile(JoinPath(dir, kContactFile), ContactCsv(t.contacts, t.manifest.fps)));
  ARCO_RETURN_IF_ERROR(AtomicWriteFile(JoinPath(dir, kNotesFile), NotesCsv(t.notes)));
  const bool double_stops = t.HasDoubleStops();
  if (double_stops) {
    if (t.second_contacts.size() != t.contacts.size())
      throw std::invalid_argument("WriteTruthFolder: contact_2 rows differ from contact rows");
    ARCO_RETURN_IF_ERROR(AtomicWriteFile(JoinPath(dir, kSecondContactFile),
                                         ContactCsv(t.second_contacts, t.manifest.fps)));
    ARCO_RETURN_IF_ERROR(
        AtomicWriteFile(JoinPath(dir, kSecondNotesFile), NotesCsv(t.second_notes)));
  }
  // A recording's pitch is not known: no pitch.csv (eval reports pitch absent).
  if (t.manifest.motion_source.empty()) {
    ARCO_RETURN_IF_ERROR(audio::WritePitchCsv(
        JoinPath(dir, kPitchFile), t.pitch, t.second_f0_hz.empty() ? nullptr : &t.second_f0_hz));
  }
  // The bow arm's truth (generated performances; a recording has none).
  if (!t.bowing.empty()) {
    ARCO_RETURN_IF_ERROR(refine::WriteBowingCsv(JoinPath(dir, kBowingFile), t.bowing));
  }
  return WriteJsonFile(JoinPath(dir, kManifestFile),
                       ManifestJson(t.manifest, !t.bowing.empty(), double_stops));
}

StatusOr<TruthFolder> ReadTruthFolder(const std::string& dir) {
  TruthFolder t;
  const std::string manifest_path = TruthManifestPath(dir);
  ARCO_ASSIGN_OR_RETURN(const Json j, ReadJsonFile(manifest_path));
  ARCO_ASSIGN_OR_RETURN(t.manifest, ManifestFromJson(j, manifest_path));
  const int64_t frames = t.manifest.frames;
  auto frames_error = [&](const std::string& path, int64_t found) {
    return Status::Error(path + ": " + std::to_string(found) + " frames, but " + manifest_path +
                         " says " + std::to_string(frames));
  };

  const std::string points_path = TruthPoints3dPath(dir);
  ARCO_ASSIGN_OR_RETURN(t.points3d, ReadNpy<double>(points_path));
  if (t.points3d.shape.size() != 3 || t.points3d.shape[2] != 3)
    return Status::Error(points_path + ": expected an array of shape (frames, points, 3)");
  if (t.points3d.shape[0] != frames) return frames_error(points_path, t.points3d.shape[0]);

  for (const auto& [file, hands] :
       {std::pair{kLeftHandPoseFile, &t.left_hand}, std::pair{kRightHandPoseFile, &t.right_hand}}) {
    const std::string path = JoinPath(dir, file);
    ARCO_ASSIGN_OR_RETURN(const NpyArray<double> params, ReadNpy<double>(path));
    ARCO_ASSIGN_OR_RETURN(*hands, hand::HandsFromParams(params, path));
    if (static_cast<int64_t>(hands->size()) != frames)
      return frames_error(path, static_cast<int64_t>(hands->size()));
  }

  const std::string pose_path = JoinPath(dir, kInstrumentPoseFile);
  ARCO_ASSIGN_OR_RETURN(const NpyArray<double> poses, ReadNpy<double>(pose_path));
  if (poses.shape.size() != 3 || poses.shape[1] != 4 || poses.shape[2] != 4)
    return Status::Error(pose_path + ": expected an array of shape (frames, 4, 4)");
  if (poses.shape[0] != frames) return frames_error(pose_path, poses.shape[0]);
  t.world_from_instrument.resize(static_cast<size_t>(frames));
  for (int64_t f = 0; f < frames; ++f) {
    for (int r = 0; r < 4; ++r) {
      for (int k = 0; k < 4; ++k)
        t.world_from_instrument[static_cast<size_t>(f)](r, k) = poses.at(f, r, k);
    }
  }

  ARCO_ASSIGN_OR_RETURN(t.contacts, refine::ReadContactsCsv(JoinPath(dir, kContactFile)));
  ARCO_ASSIGN_OR_RETURN(t.notes, ReadNotesCsv(JoinPath(dir, kNotesFile)));
  // pitch.csv may be absent (a truth without audio): nothing to score.
  const std::string pitch_path = JoinPath(dir, kPitchFile);
  if (FileExists(pitch_path)) {
    ARCO_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(pitch_path));
    ARCO_ASSIGN_OR_RETURN(t.pitch, audio::ParsePitchCsv(text, pitch_path, &t.second_f0_hz));
  }
  // contact_2.csv and notes_2.csv: a piece with double stops (truth.json lists them).
  const std::string second_path = JoinPath(dir, kSecondContactFile);
  if (FileExists(second_path)) {
    ARCO_ASSIGN_OR_RETURN(t.second_contacts, refine::ReadContactsCsv(second_path));
    if (t.second_contacts.size() != t.contacts.size()) {
      return Status::Error(second_path + ": " + std::to_string(t.second_contacts.size()) +
                           " rows, but contact.csv has " + std::to_string(t.contacts.size()));
    }
    ARCO_ASSIGN_OR_RETURN(t.second_notes, ReadNotesCsv(JoinPath(dir, kSecondNotesFile)));
  }
  bool any_second = false;
  for (double f : t.second_f0_hz) any_second |= f > 0;
  if (!any_second) t.second_f0_hz.clear();
  // bowing.csv may be absent (a recording, or a truth written before it existed).
  const std::string bowing_path = JoinPath(dir, kBowingFile);
  if (FileExists(bowing_path)) {
    ARCO_ASSIGN_OR_RETURN(t.bowing, refine::ReadBowingCsv(bowing_path));
    if (static_cast<int64_t>(t.bowing.size()) != frames)
      return frames_error(bowing_path, static_cast<int64_t>(t.bowing.size()));
  }
  return t;
}

}  // namespace arco::synth
