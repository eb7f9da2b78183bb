// `arco calibrate from-instrument CAPTURE -o CALIBRATION`: a calibration from the take
// itself, without a board (two phones; docs/calibration.md "Calibrating from the
// instrument").
//
// 1. Intrinsics: the image size from each camera's video (or image_size), fx = fy = the
//    focal length given (focal_px), or from a horizontal field of view (fov_deg), or a
//    phone's main camera by default (kPhoneFovDeg: a 26 mm-equivalent lens on a 4:3
//    sensor, whose width a video keeps); principal point at the image centre, no
//    distortion. The summary says which.
//    With labels (`--labels CAMERA=LABELS.json`, labelme files of one frame as `arco
//    track` takes them, read by mocap/labelme.h), the instrument's points come from them:
//    the labelled points are put in every frame of their camera (score 1), as if the
//    instrument stood still for the whole take, in place of keypoints2d's instrument
//    points (a starting calibration for `arco track`; docs/phones.md).
// 2. Per camera and frame, cam_from_instrument by PnP of the instrument's rigid keypoints
//    against their nominal places (instrument/nominal_keypoints.h: the model's real
//    dimensions give the metric scale): EPnP (Lepetit, Moreno-Noguer, Fua, IJCV 2009)
//    inside RANSAC, then Levenberg-Marquardt on the inliers (cv::solvePnPRansac,
//    cv::solvePnP SOLVEPNP_ITERATIVE).
// 3. The instrument moves, but in a frame every camera sees it in, camera c's pose
//    relative to the first camera, cam_c_from_cam_0 = cam_c_from_instrument *
//    inverse(cam_0_from_instrument), is what stays constant: the frame whose relative poses
//    are the medoid of all frames' (smallest median distance to the others, degrees plus
//    centimetres) gives the initial rig.
// 4. RefineCalibration (calibration_refine.h: bundle adjustment in Ceres over the
//    performer's keypoints and the instrument as a rigid body whose string length is held
//    at the model's) from that rig, with min_views 2 and the focal lengths free unless
//    fixed.
// World frame: the first capture camera's (cam_from_world of the first camera is the
// identity), millimetres.
// One camera (one phone): steps 1 and 2 only. Nothing relates it to another camera and one
// view measures no length, so its frame is the world, nothing is refined, the string
// length is not measured (NaN, with a warning), and the report's PnP RMS says how well
// the instrument's model fits its points (`arco run` poses the instrument per frame
// itself: track/monocular_lift.h).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "arco/calibrate/calibration_refine.h"
#include "arco/camera/phone_camera.h"
#include "arco/camera/rig.h"
#include "arco/util/json_io.h"
#include "arco/util/number_range.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"

namespace arco::calibrate {

using arco::kPhoneFovDeg;  // camera/phone_camera.h
inline constexpr NumberRange kFromInstrumentFocalRangePx = AboveZero(100000);
inline constexpr NumberRange kFromInstrumentFovRangeDeg = Closed(10, 150);
inline constexpr NumberRange kFromInstrumentPointsRange = Closed(4, 64);
inline constexpr NumberRange kFromInstrumentGateRangePx = AboveZero(1000);
inline constexpr NumberRange kFromInstrumentImageSideRange = Closed(0, 100000);

// One labelme file: the instrument's points labelled in `camera` (name or serial).
struct InstrumentLabelsFile {
  std::string camera;
  std::string path;
};

struct CalibrationFromInstrumentOptions {
  std::string capture_dir;
  // Set: capture_dir's capture.json as the caller already read it (the CLI's paths' check),
  // so it is read once (and handed on to the refinement); unset: read here.
  std::optional<CaptureManifest> capture_manifest;
  std::string output;        // calibration to write (.json, .yaml/.yml, .xml)
  bool overwrite = false;    // replace an existing output file
  double focal_px = 0;       // fx = fy of every camera; 0 = from fov_deg
  double fov_deg = 0;        // horizontal field of view; 0 = kPhoneFovDeg (both 0: default)
  int image_width = 0;       // 0 = from each camera's video
  int image_height = 0;      // given with image_width
  double min_score = 0.6;    // instrument detections below this confidence are ignored
  int min_points = 5;        // instrument points a view needs for a PnP
  double pnp_gate_px = 12;   // RANSAC inlier threshold of the PnP
  bool refine_focal = true;  // the bundle adjustment also refines fx, fy
  // Frames the bundle adjustment uses (RefineCalibration): more than refine's 60, as two
  // views constrain each point less (docs/calibration.md's figures).
  int max_frames = 300;
  int max_iterations = 100;  // per bundle adjustment pass
  // Labels of every camera (none: keypoints2d's instrument points) of the capture's frame
  // labels_frame (-1: the first; on the capture's clock, as `arco track --labels-frame`).
  std::vector<InstrumentLabelsFile> labels;
  int64_t labels_frame = -1;
  Status Validate() const;  // messages name the fields
};

struct FromInstrumentCamera {
  std::string name;
  int width = 0, height = 0;
  std::string size_source;                    // "video" or "--image-size"
  double initial_focal_px = 0, focal_px = 0;  // given / default, and after the refinement
  int pnp_frames = 0;                         // frames with a PnP pose of the instrument
  double pnp_rms_px = 0;                      // median over those frames of the PnP's inlier RMS
  // Spread of the per-frame relative poses about the one chosen (median; not the first
  // camera's).
  double relative_spread_deg = 0, relative_spread_mm = 0;
};

struct CalibrationFromInstrumentSummary {
  std::string capture_dir, output, instrument;
  std::string focal_source;  // "--focal-px", "--fov-deg", or "phone default (67 deg)"
  std::vector<FromInstrumentCamera> cameras;
  int shared_frames = 0;        // frames where every camera has a PnP pose
  // The capture frame (index) the initial rig comes from; one camera: none (null in the
  // report).
  int64_t reference_frame = 0;
  double string_length_mm = 0;  // the model's
  // The template's nut-to-bridge distance in the initial rig's scale (before the
  // refinement holds it at the model's): how far off the PnP scale was.
  double string_length_initial_mm = 0;
  // The nut-centre to bridge-centre distance triangulated with the refined rig in every
  // frame where both cameras see all four points: median, robust spread (1.4826 MAD) and
  // frames. An independent check of the scale (the template is held at the model's). NaN
  // (null in the report, with a warning) when no frame shows the four points in two views.
  double string_length_measured_mm = 0, string_length_spread_mm = 0;
  int string_length_frames = 0;
  double rms_initial_px = 0, rms_px = 0;  // reprojection RMS, initial rig and refined
  CalibrationRefineSummary refinement;
  std::vector<std::string> warnings;
  Rig rig;
  Json ToJson() const;
};

// Writes options.output and OUTPUT.report.json beside it through OutputSet: nothing is
// written on an error. Errors (one line naming the file): an unreadable capture, no
// instrument, an image size that cannot be read, a camera that never sees min_points
// instrument points, no frame where every camera has a pose, and RefineCalibration's;
// with labels, before any work: an unreadable or malformed file, an unknown camera, a
// camera labelled twice or not at all, a labelled frame the camera did not record, an
// image size that is not the camera's, a label outside the image, fewer than min_points
// of the instrument's points in a file. A label that is neither a point of the
// instrument nor the bow's is a warning and is ignored, as in `arco track`.
StatusOr<CalibrationFromInstrumentSummary> CalibrateFromInstrument(
    const CalibrationFromInstrumentOptions& options, Progress& progress = NoProgress());

}  // namespace arco::calibrate
