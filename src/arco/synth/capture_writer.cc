#include "arco/synth/capture_writer.h"

#include <cstdio>
#include <filesystem>
#include <sstream>

#include "arco/audio/pitch_tracker.h"
#include "arco/camera/calibration_io.h"
#include "arco/mocap/capture.h"
#include "arco/synth/synth_instrument.h"
#include "arco/util/atomic_dir.h"
#include "arco/util/file_io.h"
#include "arco/util/json_io.h"

namespace arco::synth {
namespace {

namespace fs = std::filesystem;

NpyArray<double> HandPoses(const std::vector<hand::HandPose>& poses) {
  NpyArray<double> a;
  a.shape = {static_cast<int64_t>(poses.size()), 26};
  a.data.reserve(poses.size() * 26);
  for (const hand::HandPose& p : poses) {
    const Eigen::Vector3d aa = p.WristAngleAxis();
    for (int i = 0; i < 3; ++i) a.data.push_back(aa[i]);
    for (int i = 0; i < 3; ++i) a.data.push_back(p.wrist_in_world_mm[i]);
    for (double v : p.angles_rad) a.data.push_back(v);
  }
  return a;
}

std::string ContactCsv(const SyntheticCapture& c) {
  std::ostringstream out;
  out << "frame,time_s,state,string,finger,note,f0_hz,contact_x_mm,contact_y_mm,contact_z_mm\n";
  char line[256];
  for (int f = 0; f < c.num_frames; ++f) {
    const ContactTruth& t = c.contact[static_cast<size_t>(f)];
    const char* state = t.finger > 0 ? "pressed" : (t.open_string ? "open_string" : "rest");
    std::snprintf(line,
                  sizeof(line),
                  "%d,%.6f,%s,%d,%d,%d,%.4f,%.4f,%.4f,%.4f\n",
                  f,
                  f / c.options.fps,
                  state,
                  t.string,
                  t.finger,
                  t.note_index,
                  t.f0_hz,
                  t.point_mm.x(),
                  t.point_mm.y(),
                  t.point_mm.z());
    out << line;
  }
  return out.str();
}

std::string NotesCsv(const SyntheticCapture& c) {
  std::ostringstream out;
  out << "note,onset_s,offset_s,midi_note,name,velocity,string,finger,position_semitones,"
         "intonation_cents,vibrato_rate_hz,vibrato_extent_cents\n";
  char line[256];
  const int n = static_cast<int>(c.performance.notes.size());
  const int num_strings = 4;  // every supported instrument; string 1 = highest
  for (int i = 0; i < n; ++i) {
    const PerformedNote& p = c.performance.notes[static_cast<size_t>(i)];
    std::snprintf(line,
                  sizeof(line),
                  "%d,%.6f,%.6f,%d,%s,%d,%d,%d,%d,%.3f,%.3f,%.3f\n",
                  i,
                  p.note.onset_s,
                  p.note.offset_s,
                  p.note.midi_note,
                  MidiNoteName(p.note.midi_note).c_str(),
                  p.note.velocity,
                  num_strings - p.fingering.string_index,
                  p.fingering.finger,
                  p.fingering.position_semitones,
                  p.intonation_cents,
                  p.vibrato_rate_hz,
                  p.vibrato_extent_cents);
    out << line;
  }
  return out.str();
}

Json TruthJson(const SyntheticCapture& c, const WriteOptions& w, const WriteSummary& s) {
  Json j;
  j["format"] = "arco-synth-truth";
  j["version"] = 1;
  const SynthOptions& o = c.options;
  j["instrument"] = o.instrument;
  j["piece"] = o.midi_path.empty() ? o.piece : o.midi_path;
  j["seed"] = o.seed;
  j["fps"] = o.fps;
  j["frames"] = c.num_frames;
  j["notes"] = c.performance.notes.size();
  j["pressed_frames"] = c.pressed_frames;
  j["max_residual_shift_mm"] = c.max_residual_shift_mm;
  j["layout"] = c.layout;
  j["truth_layout"] = c.truth_layout;
  j["units"] = "mm";
  j["calibration_source"] = w.calibration_source;
  j["stage"] = {{"mm_per_unit", c.stage.mm_per_unit},
                {"median_camera_distance_mm", c.stage.median_camera_distance_mm},
                {"performer_origin_in_world_mm",
                 {c.stage.performer_origin_in_world_mm.x(),
                  c.stage.performer_origin_in_world_mm.y(),
                  c.stage.performer_origin_in_world_mm.z()}}};
  j["hand_model"] = "arco default (hand/hand_model.h), left and right";
  j["detection"] = {{"noise_px", o.detection.noise_px},
                    {"outlier_rate", o.detection.outlier_rate},
                    {"occlusion_rate", o.detection.occlusion_rate},
                    {"finger_bias_mm", o.detection.finger_bias_mm}};
  j["fingering"] = {{"shifts", c.fingering.num_shifts},
                    {"open_strings", c.fingering.num_open_strings},
                    {"string_crossings", c.fingering.num_string_crossings},
                    {"total_cost", c.fingering.total_cost}};
  Json offsets = Json::object();
  for (const auto& [key, cents] : s.audio.key_offset_cents) offsets[std::to_string(key)] = cents;
  j["sample_median_offset_cents"] = offsets;
  j["files"] = {{"points3d", "points3d.npy"},
                {"left_hand_pose", "left_hand_pose.npy"},
                {"right_hand_pose", "right_hand_pose.npy"},
                {"instrument_pose", "instrument_pose.npy"},
                {"contact", "contact.csv"},
                {"pitch", "pitch.csv"},
                {"notes", "notes.csv"}};
  return j;
}

Status WriteAll(const SyntheticCapture& c,
                const std::string& dir,
                const WriteOptions& w,
                WriteSummary* s) {
  const std::string truth = JoinPath(dir, "truth");
  ARCO_RETURN_IF_ERROR(MakeDirectories(truth));
  // Calibration in mm.
  ARCO_ASSIGN_OR_RETURN(const std::string calibration, WriteArcoJson(c.rig_mm));
  ARCO_RETURN_IF_ERROR(AtomicWriteFile(JoinPath(dir, "calibration.json"), calibration));
  ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(dir, "keypoints2d.npy"), c.keypoints2d));
  // Audio.
  CaptureManifest m;
  if (w.audio) {
    ARCO_RETURN_IF_ERROR(RenderPerformanceAudio(c.performance,
                                                GmProgramFor(c.instrument_kind),
                                                w.audio_render,
                                                dir,
                                                JoinPath(dir, "performance.mid"),
                                                JoinPath(dir, "audio.wav"),
                                                c.options.seed,
                                                &s->audio));
    m.audio = "audio.wav";
  }
  m.name = "synth " + c.options.instrument + " " +
           (c.options.midi_path.empty() ? c.options.piece : c.options.midi_path) + " seed " +
           std::to_string(c.options.seed);
  m.instrument = InstrumentKindName(c.instrument_kind);
  m.fps = c.options.fps;
  m.frame_first = 1;
  m.frame_count = c.num_frames;
  m.tuning_a4_hz = c.options.a4_hz;
  m.calibration = "calibration.json";
  m.audio_offset_s = 0;
  m.keypoints2d = "keypoints2d.npy";
  m.layout = c.layout;
  for (const Camera& cam : c.rig_mm.cameras) m.cameras.push_back({cam.name, cam.serial, "", {}});
  ARCO_RETURN_IF_ERROR(WriteCaptureManifest(dir, m));
  // Truth.
  ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(truth, "points3d.npy"), c.points3d));
  ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(truth, "left_hand_pose.npy"), HandPoses(c.left_hand)));
  ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(truth, "right_hand_pose.npy"), HandPoses(c.right_hand)));
  NpyArray<double> poses;
  poses.shape = {c.num_frames, 4, 4};
  for (const Eigen::Matrix4d& p : c.world_from_instrument) {
    for (int r = 0; r < 4; ++r) {
      for (int k = 0; k < 4; ++k) poses.data.push_back(p(r, k));
    }
  }
  ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(truth, "instrument_pose.npy"), poses));
  ARCO_RETURN_IF_ERROR(AtomicWriteFile(JoinPath(truth, "contact.csv"), ContactCsv(c)));
  ARCO_RETURN_IF_ERROR(AtomicWriteFile(JoinPath(truth, "notes.csv"), NotesCsv(c)));
  // Confidence marks what a pitch evaluation should score: 0 for the first
  // 60 ms of a note (the sample speaks) and for release tails (0.7 s after a
  // note's end, the rendered sample still rings), 1 elsewhere.
  std::vector<audio::PitchFrame> pitch;
  for (int f = 0; f < c.num_frames; ++f) {
    const double t = f / c.options.fps;
    const double f0 = c.performance.F0HzAt(t);
    bool scored = true;
    for (const PerformedNote& n : c.performance.notes) {
      if (t >= n.note.onset_s && t < n.note.onset_s + 0.06) scored = false;
      if (f0 <= 0 && t >= n.note.offset_s && t < n.note.offset_s + 0.7) scored = false;
    }
    pitch.push_back({f, t, f0, scored ? 1.0 : 0.0, f0 > 0});
  }
  ARCO_RETURN_IF_ERROR(audio::WritePitchCsv(JoinPath(truth, "pitch.csv"), pitch));
  ARCO_RETURN_IF_ERROR(WriteJsonFile(JoinPath(truth, "truth.json"), TruthJson(c, w, *s)));
  return Status::Ok();
}

}  // namespace

static FolderReplace CaptureReplace(const WriteOptions& w) {
  FolderReplace r;
  r.overwrite = w.overwrite;
  r.marker = kCaptureManifestName;  // only an arco capture is replaced
  r.kind = "capture";
  return r;
}

Status CheckCaptureOutput(const std::string& out_dir, const WriteOptions& w) {
  return CheckOutputFolder(out_dir, CaptureReplace(w));
}

Status WriteCapture(const SyntheticCapture& c,
                    const std::string& out_dir,
                    const WriteOptions& w,
                    WriteSummary* summary) {
  WriteSummary local;
  WriteSummary* s = summary ? summary : &local;
  ARCO_RETURN_IF_ERROR(AtomicWriteDirectory(
      out_dir, CaptureReplace(w), [&](const std::string& tmp) { return WriteAll(c, tmp, w, s); }));
  std::error_code ec;
  const fs::path target(NormalizeOutputPath(out_dir));
  for (const auto& e : fs::recursive_directory_iterator(target, ec)) {
    if (e.is_regular_file(ec)) s->bytes += static_cast<int64_t>(e.file_size(ec));
  }
  return Status::Ok();
}

}  // namespace arco::synth
