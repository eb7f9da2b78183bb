// The result folder of `arco run` (docs/formats.md, "Result folder"): its one reader and
// one writer per output. Every file name, CSV header and result.json entry of the folder
// is spelled here (or in result_folder.cc) and nowhere else; the stages, `arco refine` and
// `arco eval` read and write through ResultFolder.
//
//   RESULT_DIR/result.json      the manifest: the capture's header (name, instrument, fps,
//                               frames, units, layout, keypoint_names, cameras) and
//                               "stages"."<stage>" = {dir, files, options, summary, ...},
//                               "options": every option of the run (RunOptions, as applied)
//   triangulation/              points3d.npy (F, P, 3) filtered, points3d_raw.npy,
//                               reprojection_rms_px.npy (F, P), inlier_count.npy,
//                               view_count.npy, inlier_mask.npy (F, P, V); world units
//   instrument/                 strings.npy (F, S, 2, 3) nut and bridge of each string,
//                               keypoints.npy (F, K, 3) the placed template; mm
//   hand/                       hand_params.npy (F, 26), bone_lengths_mm.npy (21),
//                               rest_points_mm.npy (21, 3)
//   pitch.csv, notes.csv        the audio layer's formats (audio/pitch_tracker.h,
//                               audio/notes.h), in the folder itself; with double stops
//                               double_stops.csv (audio/double_stops_csv.h)
//   vision/ paper/ arco/        points3d.npy (refine/method_result.h), hand_params.npy,
//                               contacts.csv (refine/contacts_csv.h) and fingering.csv
//                               (kFingeringCsvHeader) for paper and arco
//
// hand_params.npy rows: the left wrist rotation as an angle-axis (3, rad), the wrist
// position (3, mm), the 20 joint angles (rad, hand/hand_model.h); a NaN row is no hand.
// Each writer writes its files and its entry in result.json (keeping the earlier stages',
// removing the later ones) as one transaction (util/output_set.h): all of them or none.
//
// result.json is read at most once by an Exclusive folder: `arco run` makes one for its
// temporary result and hands it (and its copies, which share the manifest) to every
// stage, so that the run never reads back what it wrote; every other ResultFolder (the
// standalone stages, `arco refine`, `arco eval`) reads result.json from disk each time.
//
// Tied to the capture (docs/architecture.md, "Results are tied to their inputs"): every
// stage records the fingerprints of the capture files it read (capture_inputs.h) in its
// entry's "inputs", and result.json "inputs" holds them all; ReadHeader, which every
// reader of a result goes through, re-hashes them and refuses a result whose capture
// changed since. Writing a stage removes the stages after it (kStageOrder), in the same
// transaction, and names them in result.json "removed_stages": they were made from what
// it replaces.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "arco/audio/double_stops.h"
#include "arco/audio/notes.h"
#include "arco/audio/pitch_tracker.h"
#include "arco/hand/hand_model.h"
#include "arco/mocap/capture.h"
#include "arco/mocap/triangulate_sequence.h"
#include "arco/pipeline/capture_inputs.h"
#include "arco/pipeline/summaries.h"
#include "arco/refine/bowing.h"
#include "arco/refine/contact_annotation.h"
#include "arco/refine/double_stop_refine.h"
#include "arco/refine/refine.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/util/json_io.h"
#include "arco/util/npy.h"
#include "arco/util/status.h"

namespace arco {
class OutputSet;
}

namespace arco::pipeline {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr char kResultManifestName[] = "result.json";
// Stage names: the keys of result.json "stages" and the folders they write.
inline constexpr char kTriangulationStage[] = "triangulation";
inline constexpr char kInstrumentStage[] = "instrument";
inline constexpr char kHandStage[] = "hand";
inline constexpr char kPitchStage[] = "pitch";  // writes pitch.csv and notes.csv, no folder
// The order in which each stage reads the ones before it; any other stage (the method
// folders vision, paper, arco) comes after all of these and reads none of its kind.
inline constexpr const char* kStageOrder[] = {
    kTriangulationStage, kInstrumentStage, kHandStage, kPitchStage};

// fingering.csv: one row per note.
inline constexpr char kFingeringCsvHeader[] =
    "note,first_frame,last_frame,onset_s,duration_s,f0_hz,midi_note,note_name,cents_off,state,"
    "string,finger,position_semitones,from_nut_mm,pressed_frames,open_frames,uncertain_frames";

// What the triangulation stage writes besides its arrays.
struct TriangulationRecord {
  std::string capture_dir;
  std::string units;  // of the rig
  Json options;       // triangulation and filter options as run
  SequenceTriangulationSummary summary;
  CaptureInputs inputs;  // the capture files read (manifest, calibration, keypoints2d)
  // One camera: its centre (world units), which `arco refine` needs to move the hand along
  // its rays (result.json's triangulation "depth" entry).
  std::optional<Eigen::Vector3d> one_view_camera_centre;
};

// instrument/ and its entry.
struct InstrumentRecord {
  std::string instrument;  // model name (instrument/instrument_model.h)
  double a4_hz = 440.0;
  double world_units_per_mm = 0;
  std::vector<std::string> keypoint_names;  // the template's, the columns of keypoints_mm
  NpyArray<double> strings_mm;              // (F, S, 2, 3), NaN without a pose
  NpyArray<double> keypoints_mm;            // (F, K, 3), NaN without a pose
  InstrumentStageSummary summary;           // written, not read back
  CaptureInputs inputs;                     // the capture files read; written, not read back
};

// hand/ and its entry: the fitted left hand.
struct HandRecord {
  std::vector<std::optional<hand::HandPose>> hands;  // per frame
  hand::BoneLengthsMm bone_lengths_mm{};             // index = keypoint, [0] unused (0)
  // The fitted hand model's rest pose in its wrist frame (hand_model.h,
  // HandModel::rest_points_mm): the bone lengths and the performer's palm. Read from
  // rest_points_mm.npy, or made from the bone lengths for results without one.
  hand::RestPointsMm rest_points_mm =
      hand::HandModel::Default(hand::HandSide::kLeft).rest_points_mm();
  HandStageSummary summary;                          // written, not read back
  CaptureInputs inputs;  // the capture files read; written, not read back
};

// pitch.csv, notes.csv and the pitch entry.
struct PitchRecord {
  std::vector<audio::PitchFrame> frames;  // one per video frame
  // With double stops, one per video frame (double_stops.csv); empty: none, no file.
  std::vector<audio::PolyPitchFrame> double_stops;
  audio::NoteAnalysis notes;
  double a4_hz = 440.0;
  PitchStageSummary summary;  // summary.audio: the file tracked
  CaptureInputs inputs;       // the capture files read; written, not read back
};

// One method folder (vision, paper, arco) and its entry.
struct MethodRecord {
  std::string method;  // "vision", "paper", "arco"
  std::string layout;  // refine::SpdContactLayoutName
  NpyArray<double> points3d;
  std::vector<std::optional<hand::HandPose>> hands;
  std::vector<refine::FrameContact> contacts;    // empty: no contacts.csv (vision)
  // The upper notes of double stops (arco with double stops): contacts_2.csv, in
  // contacts.csv's format; empty: none.
  std::vector<refine::FrameContact> second_contacts;
  // Their notes (fingering_2.csv, fingering.csv's format); empty: none.
  std::vector<refine::NoteFingering> second_fingering;
  // Recorded as the stage's "double_stops" (options and counts) when second_contacts is.
  refine::DoubleStopRefineOptions double_stop_options;
  refine::DoubleStopRefineSummary double_stop_summary;
  std::vector<refine::NoteFingering> fingering;  // written with contacts
  refine::RefineOptions options;                 // as applied (refine::ToJson)
  refine::RefineSummary summary;
  std::optional<refine::BowingResult> bowing;  // arco's: bowing.csv, bowing_notes.csv
  refine::BowingOptions bowing_options;
};

// A stage with 3D points, as `arco eval` finds them.
struct PointStage {
  std::string name;
  std::string points3d_path;
  std::vector<std::string> keypoint_names;  // empty: the result's
  std::string contacts_path;                // empty: none
  std::string second_contacts_path;         // contacts_2.csv, double stops; empty: none
  std::string bowing_path;                  // empty: none (refine/bowing.h)
};

// The capture header of result.json (with the defaults of a manifest that lacks them).
struct ResultHeader {
  std::string units = "unknown";
  double fps = 30.0;  // 30 when absent
  int64_t frame_first = 1;
  int64_t frame_count = 0;
  std::vector<std::string> keypoint_names;
  std::string capture_dir;  // "capture", resolved against the result folder ("" when absent)
};

// Whether ReadHeader compares the capture files with their recorded fingerprints.
enum class InputCheck {
  kCompare,  // every reader of a result
  kSkip,     // only to list the paths a command touches (cli/command_paths.h)
};

class ResultFolder {
 public:
  // Reads result.json from disk whenever it needs it: the folder may have been written
  // by anyone since.
  explicit ResultFolder(std::string dir) : dir_(std::move(dir)) {}
  // A folder that this object and its copies alone write, one call at a time, while they
  // live (`arco run`'s hidden temporary result): they share the manifest, read from disk
  // at most once (an absent one is empty), then the one their last write committed, so
  // that nothing the run wrote is read back. A failed write leaves it as it was (the
  // manifest changes only once its OutputSet is committed).
  static ResultFolder Exclusive(std::string dir);

  const std::string& dir() const { return dir_; }
  // Throws std::invalid_argument (a caller bug) when `result_dir` is not dir(): a stage
  // given both its options' result_dir and a ResultFolder writes the one named by both.
  void RequireDir(const std::string& result_dir) const;
  std::string ManifestPath() const;
  // RESULT_DIR/<stage>/<file>.
  std::string StagePath(const std::string& stage, const std::string& file) const;
  // The files' paths, for messages about their contents.
  std::string Points3dPath(const std::string& stage) const;
  std::string InstrumentStringsPath() const;
  std::string InstrumentKeypointsPath() const;
  std::string HandParamsPath() const;
  std::string BoneLengthsPath() const;

  // Before the work: the folder can be created, or is empty, or is an arco result folder
  // (holds result.json), never some other folder whose stage-named subfolders would be
  // replaced.
  Status CheckWritable() const;

  // result.json: an empty object when absent; an error when it is not an arco result.
  // An Exclusive folder's is the one held once read or written.
  StatusOr<Json> ReadManifest() const;
  // With kCompare, CheckInputs first: a result whose capture changed is an error.
  StatusOr<ResultHeader> ReadHeader(InputCheck check = InputCheck::kCompare) const;

  // Re-hashes every capture file result.json records ("inputs", and each stage's) and
  // compares: one that differs or is gone is the error "FILE changed since the result
  // DIR was made (re-run `arco run`)". A result without recorded inputs (written before
  // arco recorded them) passes: there is nothing to compare.
  Status CheckInputs() const;
  // The same comparison against fingerprints already taken (a stage of `arco run` given
  // the capture it opened): the roles both have must agree.
  Status CheckInputsMatch(const CaptureInputs& capture) const;
  StatusOr<bool> HasStage(const std::string& stage) const;
  // The stages whose entry lists a points3d file, in result.json's order.
  StatusOr<std::vector<PointStage>> PointStages() const;

  // triangulation/ and the capture header of result.json, which starts anew: its
  // "inputs" are the triangulation's, the run's "options" go, and so do the later stages
  // (kStageOrder), whose names it returns.
  StatusOr<std::vector<std::string>> WriteTriangulation(const CaptureManifest& manifest,
                                                        const KeypointLayout& layout,
                                                        const SequenceTriangulation& raw,
                                                        const NpyArray<double>& points3d_filtered,
                                                        const TriangulationRecord& record) const;
  // <stage>/points3d.npy of any stage (triangulation, vision, paper, arco).
  StatusOr<NpyArray<double>> ReadPoints3d(const std::string& stage) const;
  // triangulation/reprojection_rms_px.npy and inlier_count.npy, each (F, P) in the
  // result's layout (NaN / 0 where a point was not triangulated); shapes unchecked.
  struct TriangulationQuality {
    NpyArray<float> rms_reprojection_px;
    NpyArray<int32_t> num_inliers;
  };
  StatusOr<TriangulationQuality> ReadTriangulationQuality() const;

  Status WriteInstrument(const InstrumentRecord& record) const;
  // The scale recorded by the instrument stage; an error naming result.json without one.
  StatusOr<double> ReadWorldUnitsPerMm() const;
  // Entry (instrument, a4_hz, world_units_per_mm) and both arrays, shapes unchecked.
  StatusOr<InstrumentRecord> ReadInstrument() const;

  Status WriteHand(const HandRecord& record) const;
  // Errors: a hand_params.npy not (F, 26), a bone_lengths_mm.npy not (21), a
  // rest_points_mm.npy not (21, 3) or not a valid hand.
  StatusOr<HandRecord> ReadHand() const;

  Status WritePitch(const PitchRecord& record) const;
  StatusOr<std::vector<audio::PitchFrame>> ReadPitch() const;
  std::string PitchPath() const;
  // double_stops.csv (audio/double_stops_csv.h); empty when the result has none.
  StatusOr<std::vector<audio::PolyPitchFrame>> ReadDoubleStops() const;
  // The notes of notes.csv (empty when the file is absent: results of older versions).
  StatusOr<std::vector<audio::Note>> ReadNotes() const;

  Status WriteMethod(const MethodRecord& record) const;
  std::string ContactsPath(const std::string& method) const;
  std::string FingeringPath(const std::string& method) const;
  // <method>/fingering.csv (kFingeringCsvHeader; columns found by name), empty when the
  // method has none (vision). Errors name the file and line: a missing column, a short
  // row, an unparsable number.
  StatusOr<std::vector<refine::NoteFingering>> ReadFingering(const std::string& method) const;
  // <method>/fingering_2.csv: the second voice of double stops, one row per first-voice
  // note that has one (refine/transcription.h, TranscribeSecondVoice), in fingering.csv's
  // format; empty when the method has none.
  StatusOr<std::vector<refine::NoteFingering>> ReadSecondFingering(const std::string& method) const;
  // A method's bowing_notes.csv (refine/bowing.h); empty when it has none.
  StatusOr<std::vector<refine::BowingNote>> ReadBowingNotes(const std::string& method) const;

  // result.json "options": every option `arco run` applied (pipeline::ToJson(RunOptions)),
  // written once all stages are done.
  Status WriteRunOptions(const Json& options) const;

 private:
  // Writes RESULT_DIR/<stage>/ and result.json "stages"."<stage>" = `entry` plus "dir"
  // and "inputs" (earlier stages kept, later ones removed; the manifest is created when
  // absent) as one OutputSet: both or neither.
  Status WriteStageFolder(const std::string& stage,
                          const std::function<Status(const std::string& dir)>& write,
                          Json entry,
                          const CaptureInputs& inputs) const;
  // Declares in `outputs` the removal of every stage after `stage` and drops their
  // entries from `manifest`, naming them in "removed_stages"; returns their names.
  StatusOr<std::vector<std::string>> RemoveLaterStages(const std::string& stage,
                                                       OutputSet* outputs,
                                                       Json* manifest) const;
  // Once `manifest` is committed as result.json: an Exclusive folder holds it.
  void Committed(const Json& manifest) const;

  std::string dir_;
  // An Exclusive folder's result.json, shared by its copies; null: read from disk.
  struct HeldManifest {
    std::optional<Json> manifest;  // empty until read or written
  };
  std::shared_ptr<HeldManifest> held_;
};

// A fingering.csv (kFingeringCsvHeader; columns found by name), empty when the file is
// absent. Errors name the file and line.
StatusOr<std::vector<refine::NoteFingering>> ReadFingeringCsv(const std::string& path);

// Point `point` of frame `frame` of a (F, P, 3) points array (NaN where missing).
inline Eigen::Vector3d PointAt(const NpyArray<double>& points, int64_t frame, int64_t point) {
  return Eigen::Vector3d(
      points.at(frame, point, 0), points.at(frame, point, 1), points.at(frame, point, 2));
}

}  // namespace arco::pipeline
