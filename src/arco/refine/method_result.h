// The refinement's outputs in a result folder (docs/formats.md, "Method folders"): one
// folder per method (vision, paper, arco) that `arco eval` compares.
//
//   RESULT_DIR/<method>/points3d.npy     (F, 155, 3) cello / (F, 153, 3) violin, float64,
//                                        millimetres, NaN = missing: the SPD-compatible
//                                        layout spd_cello_contact / spd_violin_contact
//                                        (mocap/keypoint_layout.h; DOMAIN.md section 3)
//   RESULT_DIR/<method>/hand_params.npy  (F, 26) float64: left wrist rotation as an
//                                        angle-axis (3, rad), wrist position (3, mm), the
//                                        20 joint angles (rad, hand/hand_model.h); NaN row
//                                        = no hand
//   RESULT_DIR/<method>/contacts.csv     paper, arco: one row per frame (kContactsCsvHeader);
//                                        frame = row of the arrays, from 0
//   RESULT_DIR/<method>/fingering.csv    paper, arco: one row per note (kFingeringCsvHeader)
// and RESULT_DIR/result.json "stages"."<method>" = {dir, files (points3d, hand_params,
// contact, fingering), layout, keypoint_names, units, options, summary}.
// The folder is written whole or not at all (temporary folder + rename).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "arco/hand/hand_model.h"
#include "arco/instrument/instrument_model.h"
#include "arco/instrument/strings.h"
#include "arco/refine/contact_annotation.h"
#include "arco/util/json_io.h"
#include "arco/util/npy.h"
#include "arco/util/status.h"

namespace arco::refine {

// string, finger and contact_*_mm describe a pressed contact only (0 / NaN otherwise, the
// columns `arco eval` reads, as truth/contact.csv); open_string names the sounding open
// string on open-string frames.
inline constexpr char kContactsCsvHeader[] =
    "frame,state,reason,string,finger,note,contact_x_mm,contact_y_mm,contact_z_mm,from_nut_mm,"
    "f0_hz,confidence,tip_distance_vision_mm,tip_distance_refined_mm,open_string";
inline constexpr char kFingeringCsvHeader[] =
    "note,first_frame,last_frame,onset_s,duration_s,f0_hz,midi_note,note_name,cents_off,state,"
    "string,finger,position_semitones,from_nut_mm,pressed_frames,open_frames,uncertain_frames";

// The SPD-compatible layout name of an instrument ("spd_cello_contact", ...).
std::string SpdContactLayoutName(const InstrumentModel& model);

// What every method shares when its points3d.npy is assembled.
struct SpdSources {
  const InstrumentModel* instrument = nullptr;
  hand::HandModel hand_model = hand::HandModel::Default(hand::HandSide::kLeft);
  // (F, 133 + instrument keypoints, 3) in mm: body, right hand, instrument and bow (the
  // left hand's rows are replaced from each method's hands where it has one).
  NpyArray<double> base_points_mm;
  // Per frame, index = string - 1, world mm; empty = none (string points NaN).
  std::vector<std::vector<StringSegment>> strings_in_world_mm;
};

// (F, 133 + instrument keypoints + 13, 3): the base points, the left hand (91-111) by
// forward kinematics of `hands`, then the contact stage (DOMAIN.md section 3): the strings
// as (nut, bridge) pairs from the lowest string to the highest, the contact point, and the
// playing finger's MCP, PIP, DIP and tip on pressed frames (NaN otherwise). `contacts` may
// be null (vision). Throws std::invalid_argument when sizes disagree.
NpyArray<double> BuildSpdPoints(const SpdSources& sources,
                                const std::vector<std::optional<hand::HandPose>>& hands,
                                const std::vector<FrameContact>* contacts);

// (F, 26), see the header comment.
NpyArray<double> HandParams(const std::vector<std::optional<hand::HandPose>>& hands);
// The inverse; rows with any NaN are no hand. Errors on a wrong shape.
StatusOr<std::vector<std::optional<hand::HandPose>>> HandsFromParams(const NpyArray<double>& params,
                                                                     const std::string& source);

struct MethodOutput {
  std::string method;  // "vision", "paper", "arco"
  std::string layout;  // SpdContactLayoutName
  NpyArray<double> points3d;
  std::vector<std::optional<hand::HandPose>> hands;
  std::vector<FrameContact> contacts;    // empty: no contacts.csv (vision)
  std::vector<NoteFingering> fingering;  // written with contacts
  Json options;
  Json summary;
};

// Writes RESULT_DIR/<method>/ and its entry in result.json (other stages kept).
Status WriteMethodResult(const std::string& result_dir, const MethodOutput& output);

// Sets result.json "stages"."<stage>" = entry (other stages kept; the manifest is created
// when absent).
Status RecordStage(const std::string& result_dir, const std::string& stage, const Json& entry);

// Writes RESULT_DIR/<stage>/ whole or not at all: `write` fills a temporary folder, which
// then replaces the stage folder; result.json "stages"."<stage>" becomes `entry` plus
// "dir" (other stages kept; the manifest is created when absent).
Status WriteStageFolder(const std::string& result_dir,
                        const std::string& stage,
                        const std::function<Status(const std::string& dir)>& write,
                        Json entry);

// One row of contacts.csv, as read back (for `arco eval` and tools).
struct ContactRow {
  int64_t frame = 0;
  std::string state;  // pressed, open, rest, uncertain
  std::string reason;
  int string = 0, finger = 0, note = -1, open_string = 0;
  Eigen::Vector3d point_mm = Eigen::Vector3d::Constant(kNaN);
  double from_nut_mm = kNaN, f0_hz = 0, confidence = 0;
  double tip_distance_vision_mm = kNaN, tip_distance_refined_mm = kNaN;
};
// Errors name the file and line: a wrong header, a short row, an unparsable number.
StatusOr<std::vector<ContactRow>> ReadContactsCsv(const std::string& path);

}  // namespace arco::refine
