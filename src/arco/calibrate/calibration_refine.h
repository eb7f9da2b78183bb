// `arco calibrate refine CAPTURE -o CALIBRATION`: the extrinsics (and optionally the focal
// lengths) of a rough or drifted calibration refined by bundle adjustment over the capture's
// own 2D keypoints (docs/calibration.md "Refining with the performer").
//
// Unknowns: every camera's pose (cam_from_world), optionally fx and fy; one 3D point per
// performer keypoint and frame (body, face, hands, bow), triangulated from at least
// min_views cameras; the instrument as one rigid body: its tracked points (scroll, nut,
// bridge, tail gut, end pin) in its own frame, shared by all frames (initialised by
// instrument/template_fit.h), and one pose per frame.
// Residuals: reprojection of every selected detection through arco's camera model
// (PixelFromPointInCamera, distortion included), robust loss; plus one residual that holds
// the template's nut-centre to bridge-centre distance at the instrument model's string
// length (template_fit.h's scale), which is what gives the rig its metric scale.
// Gauge (the 7 degrees of freedom no image measures): the reference camera's pose is kept
// fixed (rotation and position: the world frame stays the input's as seen from that
// camera); the scale comes from the string length.
// Robustness: three passes. Pass 1 triangulates with a wide gate (the input may be
// degrees off) and solves with a Cauchy loss; passes 2 and 3 re-triangulate with the
// refined rig, keep only views within a tighter gate and points still seen by min_views
// cameras, and solve again (Cauchy, loss_scale_px in the last pass).
// This file reads the capture, triangulates and fits the instrument; each pass's solve is
// calibration/bundle_adjustment.h's AdjustRig.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "arco/camera/calibration_io.h"
#include "arco/camera/rig.h"
#include "arco/mocap/capture.h"
#include "arco/util/json_io.h"
#include "arco/util/npy.h"
#include "arco/util/number_range.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"

namespace arco::calibrate {

inline constexpr NumberRange kRefineMaxFramesRange = Closed(1, 100000);
inline constexpr NumberRange kRefineGateRangePx = AboveZero(10000);
inline constexpr NumberRange kRefineLossRangePx = AboveZero(1000);
inline constexpr NumberRange kRefineIterationsRange = Closed(1, 10000);

struct CalibrationRefineOptions {
  std::string capture_dir;
  // Set: capture_dir's capture.json as the caller already read it (`arco calibrate refine`
  // reads it once to list the capture's files for its paths' check), so it is read once;
  // unset: read here.
  std::optional<CaptureManifest> capture_manifest;
  std::string calibration;  // "" = the capture's own; else this file is refined
  // Set: this rig is refined (calibration, if set, only names it in messages), as
  // `arco calibrate from-instrument` does with the rig it made.
  std::optional<Rig> input_rig;
  // Set: these 2D keypoints (the capture's frames and layout, as ReadCaptureKeypoints2d
  // gives them) instead of the capture's keypoints2d file, as `arco calibrate
  // from-instrument --labels` does with the labelled instrument points put in.
  const NpyArray<double>* input_keypoints = nullptr;
  std::string output;            // calibration to write (.json, .yaml/.yml, .xml)
  bool write = true;             // false: nothing is written, the summary only (output unused)
  bool overwrite = false;        // replace an existing output file
  std::string reference_camera;  // "" = the calibration's first capture camera: held fixed
  bool refine_focal = false;     // also fx, fy of every camera
  double min_score = 0.6;        // detections below this confidence are ignored
  int min_views = 3;             // a point must be seen by this many cameras (inliers)
  int max_frames = 60;           // frames used at most, evenly spread over the capture
  double initial_gate_px = 200;  // pass 1: views farther than this from the point are left out
  double gate_px = 8;            // last pass: views within this residual are kept
  double loss_scale_px = 2;      // Cauchy loss scale of the last pass
  int max_iterations = 100;      // per pass
  Status Validate() const;       // messages name the fields
};

struct CameraRefinement {
  std::string name;
  int64_t observations = 0;  // detections in the last pass
  // RMS reprojection over the last pass's detections, points triangulated with the input
  // calibration (before) and with the refined one (after).
  double rms_before_px = 0, rms_after_px = 0;
  double rotation_change_deg = 0;  // angle between the input and refined orientations
  double centre_change_mm = 0;     // distance between the camera centres (world units x mm)
  double focal_change_rel = 0;     // refined fx / input fx - 1
  bool reference = false;          // the gauge camera (held fixed)
};

struct CalibrationRefineSummary {
  std::string calibration;  // the input calibration file
  std::string output;
  std::string units;  // the rig's units (kept)
  std::string reference_camera;
  int64_t frames = 0;             // frames used
  int64_t points = 0;             // performer 3D points in the last pass
  int64_t instrument_frames = 0;  // frames with an instrument pose
  int instrument_points = 0;      // template points of the rigid body
  // Nut-centre to bridge-centre distance of the instrument template (mm): the model's
  // string length, and the input calibration's (the input rig's scale error).
  double string_length_mm = 0, string_length_before_mm = 0;
  double rms_before_px = 0, rms_after_px = 0;
  std::vector<CameraRefinement> cameras;
  struct Pass {
    std::string termination;
    int iterations = 0;
    double initial_cost = 0, final_cost = 0;
    int64_t residual_blocks = 0;
    double time_s = 0;
  };
  std::vector<Pass> passes;
  std::vector<std::string> warnings;
  Rig rig;  // the refined calibration (what was written)
  Json ToJson() const;
};

// The format a calibration output's extension names; an error naming `path` otherwise.
StatusOr<CalibrationFormat> CalibrationOutputFormat(const std::string& path);
// OUTPUT.report.json beside a calibration output (its extension replaced).
std::string RefineReportPath(const std::string& output);

// Writes options.output (and OUTPUT.report.json beside it) through OutputSet: nothing is
// written on an error. Errors: the capture or calibration cannot be read, an output that
// exists without overwrite, fewer than two cameras, an unknown reference camera, too few
// keypoints seen by min_views cameras (the message says how many), no instrument points
// when the rig is not in mm or m (no other scale).
StatusOr<CalibrationRefineSummary> RefineCalibration(const CalibrationRefineOptions& options,
                                                     Progress& progress = NoProgress());

}  // namespace arco::calibrate
