// The synthetic truth folder (CAPTURE/truth/, docs/synth.md): its one writer (called by
// capture_writer.cc) and its one reader (called by `arco eval`, eval/evaluate.cc). Every
// file name and CSV header of the folder is spelled in truth_folder.cc and nowhere else;
// pitch.csv is the audio layer's format (audio/pitch_tracker.h) and contact.csv is read by
// the one contact CSV reader (refine/contacts_csv.h), by column name.
//
//   truth.json             TruthManifest: summary, options, layouts, stage, sample tuning
//   points3d.npy           (F, P, 3) float64 mm in truth_layout order
//   left_hand_pose.npy, right_hand_pose.npy
//                          (F, 26) hand::HandParams rows (hand/hand_params.h)
//   instrument_pose.npy    (F, 4, 4) world_from_instrument (mm)
//   contact.csv            frame,time_s,state,string,finger,note,f0_hz,contact_x_mm,
//                          contact_y_mm,contact_z_mm (time_s = frame / fps)
//   pitch.csv              frame,time_s,f0_hz,confidence,voiced (confidence 0: not scored)
//   notes.csv              one row per note: timing, pitch, fingering, expression
//   contact_2.csv          only when the piece has double stops: the upper note of each
//                          (contact.csv's format and rows; state rest on frames without
//                          one, note = the double stop's row in notes.csv)
//   notes_2.csv            only with double stops: one row per double stop, its upper
//                          note (notes.csv's format; numbered 0.. in the order of the
//                          double stops)
//   (pitch.csv then also has the column f0_2_hz: the upper note's f0, 0 without one)
//   bowing.csv             the bow arm per frame (refine/bowing.h's format: string,
//                          direction, sounding_point_mm, bow_position); absent for a
//                          re-captured recording
//
// The CSVs print fixed decimals (contact.csv 4 for mm and Hz, notes.csv 6 for seconds and 3
// for cents and Hz): values read back equal the written ones only to that precision.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "arco/audio/pitch_tracker.h"
#include "arco/hand/hand_model.h"
#include "arco/refine/bowing.h"
#include "arco/refine/contacts_csv.h"
#include "arco/util/npy.h"
#include "arco/util/json_io.h"
#include "arco/util/status.h"

namespace arco::synth {

inline constexpr char kTruthFolderName[] = "truth";  // inside the capture folder

// truth.json.
struct TruthManifest {
  std::string instrument;
  std::string piece;  // built-in piece name or the MIDI file's path
  uint64_t seed = 0;
  double fps = 30;
  int64_t frames = 0;
  int64_t notes = 0;
  int64_t pressed_frames = 0;
  double max_residual_shift_mm = 0;
  std::string layout;        // the capture's keypoint layout
  std::string truth_layout;  // the columns of points3d.npy (layout + contact points)
  std::string units = "mm";
  std::string calibration_source;
  // The stage the performer was placed on.
  double mm_per_unit = 1;
  double median_camera_distance_mm = 0;
  Eigen::Vector3d performer_origin_in_world_mm = Eigen::Vector3d::Zero();
  std::string hand_model;
  // Detection noise (synth/detections.h).
  double noise_px = 0, outlier_rate = 0, occlusion_rate = 0, finger_bias_mm = 0;
  // The fingering plan (synth/fingering.h).
  int fingering_shifts = 0, fingering_open_strings = 0, fingering_string_crossings = 0;
  double fingering_total_cost = 0;
  std::map<int, double> sample_median_offset_cents;  // per MIDI key of the rendered samples
  // A re-captured recording (synth/motion.h): the motion and audio it came from ("" for a
  // generated performance) and the detector error model with every parameter
  // (synth/error_model.h; null when not recorded).
  std::string motion_source, audio_source;
  Json error_model;
  // Double stops in the score (written only when > 0: contact_2.csv, notes_2.csv).
  int64_t double_stops = 0;
};

// One row of notes.csv.
struct TruthNote {
  double onset_s = 0, offset_s = 0;
  int midi_note = 60;  // name: MidiNoteName(midi_note), written, not read back
  int velocity = 80;
  int string = 0;  // 1 = highest string
  int finger = 0;  // 0 = open string
  int position_semitones = 0;
  double intonation_cents = 0, vibrato_rate_hz = 0, vibrato_extent_cents = 0;
};

struct TruthFolder {
  TruthManifest manifest;
  NpyArray<double> points3d;                              // (F, P, 3) mm
  std::vector<std::optional<hand::HandPose>> left_hand;   // F
  std::vector<std::optional<hand::HandPose>> right_hand;  // F
  std::vector<Eigen::Matrix4d> world_from_instrument;     // F
  // One row per frame; state pressed, open_string or rest; string 1 = highest, 0 = none;
  // point_mm NaN unless pressed. Written columns only (see the header comment).
  std::vector<refine::ContactRow> contacts;
  std::vector<audio::PitchFrame> pitch;  // one per frame
  std::vector<TruthNote> notes;
  std::vector<refine::BowingFrame> bowing;  // one per frame, or empty: no bow truth
  // Double stops (all empty for a single-note piece): contact_2.csv's rows (one per frame),
  // notes_2.csv's, and pitch.csv's f0_2_hz (one per pitch row).
  std::vector<refine::ContactRow> second_contacts;
  std::vector<TruthNote> second_notes;
  std::vector<double> second_f0_hz;
  bool HasDoubleStops() const { return !second_contacts.empty(); }
};

// Paths of files inside a truth folder `dir`, for messages about their contents.
std::string TruthManifestPath(const std::string& dir);
std::string TruthPoints3dPath(const std::string& dir);

// Writes every file into `dir` (created when absent); each file atomically.
Status WriteTruthFolder(const std::string& dir, const TruthFolder& truth);
// Reads `dir` back. Errors name the file: a missing file (pitch.csv may be absent: empty),
// a truth.json of another format or without its layouts, fps or frames, arrays whose
// shape disagrees with truth.json's frames, malformed CSV rows.
StatusOr<TruthFolder> ReadTruthFolder(const std::string& dir);

}  // namespace arco::synth
