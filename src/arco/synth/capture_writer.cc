#include "arco/synth/capture_writer.h"

#include <cstdio>
#include <filesystem>
#include <sstream>

#include "arco/audio/pitch_tracker.h"
#include "arco/camera/calibration_io.h"
#include "arco/mocap/capture.h"
#include "arco/synth/synth_instrument.h"
#include "arco/synth/truth_folder.h"
#include "arco/util/atomic_dir.h"
#include "arco/util/file_io.h"
#include "arco/util/json_io.h"

namespace arco::synth {
namespace {

namespace fs = std::filesystem;

// The truth folder's contents (synth/truth_folder.h) of a generated capture.
TruthFolder MakeTruthFolder(const SyntheticCapture& c,
                            const WriteOptions& w,
                            const WriteSummary& s) {
  TruthFolder t;
  TruthManifest& m = t.manifest;
  const SynthOptions& o = c.options;
  m.instrument = o.instrument;
  m.piece = o.midi_path.empty() ? o.piece : o.midi_path;
  m.seed = o.seed;
  m.fps = o.fps;
  m.frames = c.num_frames;
  m.notes = static_cast<int64_t>(c.performance.notes.size());
  m.pressed_frames = c.pressed_frames;
  m.max_residual_shift_mm = c.max_residual_shift_mm;
  m.layout = c.layout;
  m.truth_layout = c.truth_layout;
  m.units = "mm";
  m.calibration_source = w.calibration_source;
  m.mm_per_unit = c.stage.mm_per_unit;
  m.median_camera_distance_mm = c.stage.median_camera_distance_mm;
  m.performer_origin_in_world_mm = c.stage.world_from_performer.translation;
  m.hand_model = "arco default (hand/hand_model.h), left and right";
  m.noise_px = o.detection.noise_px;
  m.outlier_rate = o.detection.outlier_rate;
  m.occlusion_rate = o.detection.occlusion_rate;
  m.finger_bias_mm = o.detection.finger_bias_mm;
  m.fingering_shifts = c.fingering.num_shifts;
  m.fingering_open_strings = c.fingering.num_open_strings;
  m.fingering_string_crossings = c.fingering.num_string_crossings;
  m.fingering_total_cost = c.fingering.total_cost;
  m.sample_median_offset_cents = s.audio.key_offset_cents;
  m.motion_source = c.motion_source;
  m.audio_source = c.audio_source;
  m.error_model = c.error_model;
  const bool recorded = !c.motion_source.empty();
  if (recorded) {
    m.piece = c.motion_source;
    m.hand_model = "none (recorded motion: no hand pose truth)";
  }

  t.points3d = c.points3d;
  const size_t frames = static_cast<size_t>(c.num_frames);
  t.left_hand.assign(c.left_hand.begin(), c.left_hand.end());
  t.right_hand.assign(c.right_hand.begin(), c.right_hand.end());
  t.left_hand.resize(frames);  // no hand pose truth: NaN rows
  t.right_hand.resize(frames);
  t.world_from_instrument = c.world_from_instrument;
  t.bowing = c.bowing;
  for (int f = 0; f < c.num_frames; ++f) {
    const ContactTruth& truth = c.contact[static_cast<size_t>(f)];
    refine::ContactRow r;
    r.frame = f;
    r.state = truth.finger > 0 ? "pressed" : (truth.open_string ? "open_string" : "rest");
    r.string = truth.string;
    r.finger = truth.finger;
    r.note = truth.note_index;
    r.f0_hz = truth.f0_hz;
    r.point_mm = truth.point_mm;
    t.contacts.push_back(r);
  }
  // The double stops' upper notes (contact_2.csv, notes_2.csv): only for a score that has
  // some, so a single-note capture's truth is as before.
  bool has_double_stops = false;
  for (const PerformedNote& p : c.performance.notes) has_double_stops |= p.note.IsDoubleStop();
  for (int f = 0; f < c.num_frames && has_double_stops; ++f) {
    const ContactTruth& truth = c.contact[static_cast<size_t>(f)];
    refine::ContactRow r;
    r.frame = f;
    r.state = !truth.double_stop ? "rest" : (truth.second_finger > 0 ? "pressed" : "open_string");
    r.string = truth.second_finger > 0 ? truth.second_string : 0;  // as contact.csv: pressed
    r.finger = truth.second_finger;
    r.note = truth.double_stop ? truth.note_index : -1;
    r.f0_hz = truth.second_f0_hz;
    r.point_mm = truth.second_point_mm;
    t.second_contacts.push_back(r);
  }
  const int num_strings = 4;  // every supported instrument; string 1 = highest
  for (const PerformedNote& p : c.performance.notes) {
    TruthNote n;
    n.onset_s = p.note.onset_s;
    n.offset_s = p.note.offset_s;
    n.midi_note = p.note.midi_note;
    n.velocity = p.note.velocity;
    n.string = num_strings - p.fingering.string_index;
    n.finger = p.fingering.finger;
    n.position_semitones = p.fingering.position_semitones;
    n.intonation_cents = p.intonation_cents;
    n.vibrato_rate_hz = p.vibrato_rate_hz;
    n.vibrato_extent_cents = p.vibrato_extent_cents;
    t.notes.push_back(n);
    if (!p.note.IsDoubleStop()) continue;
    n.midi_note = p.note.second_midi_note;
    n.string = num_strings - p.fingering.second_string_index;
    n.finger = p.fingering.second_finger;
    n.intonation_cents = p.second_intonation_cents;
    if (n.finger == 0) n.vibrato_rate_hz = n.vibrato_extent_cents = 0;
    t.second_notes.push_back(n);
  }
  m.double_stops = static_cast<int64_t>(t.second_notes.size());
  if (recorded) return t;  // the recording's pitch is not known: no pitch.csv truth
  // Confidence marks what a pitch evaluation should score: 0 for the first
  // 60 ms of a note (the sample speaks) and for release tails (0.7 s after a
  // note's end, the rendered sample still rings), 1 elsewhere.
  for (int f = 0; f < c.num_frames; ++f) {
    const double time_s = f / c.options.fps;
    const double f0 = c.performance.F0HzAt(time_s);
    bool scored = true;
    for (const PerformedNote& n : c.performance.notes) {
      if (time_s >= n.note.onset_s && time_s < n.note.onset_s + 0.06) scored = false;
      if (f0 <= 0 && time_s >= n.note.offset_s && time_s < n.note.offset_s + 0.7) scored = false;
    }
    t.pitch.push_back({f, time_s, f0, scored ? 1.0 : 0.0, f0 > 0});
    if (has_double_stops) t.second_f0_hz.push_back(c.performance.SecondF0HzAt(time_s));
  }
  return t;
}

Status WriteAll(const SyntheticCapture& c,
                const std::string& dir,
                const WriteOptions& w,
                WriteSummary* s) {
  const std::string truth = JoinPath(dir, kTruthFolderName);
  ARCO_RETURN_IF_ERROR(MakeDirectories(truth));
  // Calibration in mm.
  ARCO_ASSIGN_OR_RETURN(const std::string calibration, WriteArcoJson(c.rig_mm));
  ARCO_RETURN_IF_ERROR(AtomicWriteFile(JoinPath(dir, "calibration.json"), calibration));
  ARCO_RETURN_IF_ERROR(WriteNpy(JoinPath(dir, "keypoints2d.npy"), c.keypoints2d));
  // Audio.
  CaptureManifest m;
  if (!c.audio_source.empty()) {
    // A recording's own audio, copied as it is (its format and rate kept).
    std::string extension = fs::path(c.audio_source).extension().string();
    if (extension.empty()) extension = ".wav";
    const std::string name = "audio" + extension;
    std::error_code ec;
    fs::copy_file(c.audio_source, JoinPath(dir, name), ec);
    if (ec) return Status::Error(c.audio_source + ": cannot copy into the capture: " + ec.message());
    m.audio = name;
  } else if (w.audio) {
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
           (!c.motion_source.empty() ? fs::path(c.motion_source).filename().string()
            : c.options.midi_path.empty() ? c.options.piece
                                          : c.options.midi_path) +
           " seed " + std::to_string(c.options.seed);
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
  return WriteTruthFolder(truth, MakeTruthFolder(c, w, *s));
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
