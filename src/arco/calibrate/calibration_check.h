// `arco calibrate check CAPTURE_OR_RESULT`: is the calibration still consistent with the
// capture's own 2D keypoints? Every keypoint seen by enough cameras is triangulated
// (robustly, mocap/triangulate_point.h) or, for a result folder, taken from the result's
// triangulation (triangulation/points3d.npy, against the capture result.json names), and
// each camera's reprojection residuals are gathered over the frames; a camera whose median residual
// stands out from the rig's (a camera that moved or was mis-calibrated) is flagged, with the frames
// where it is off.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "arco/util/json_io.h"
#include "arco/util/number_range.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"

namespace arco::calibrate {

inline constexpr NumberRange kCheckRatioRange = Closed(1, 1000);
inline constexpr NumberRange kCheckMinFlagRangePx = AboveZero(10000);

struct CalibrationCheckOptions {
  std::string capture_dir;  // a capture folder or a result folder (holds result.json), or
  // labelled views instead (labelme files, corner pixel origin as labelme writes them):
  // (camera name or serial, file) per view; `calibration` is then required.
  std::vector<std::pair<std::string, std::string>> label_views;
  std::string calibration;   // "" = the capture's own; else this file is checked
  double min_score = 0.5;    // detections below this confidence are ignored
  int min_views = 3;         // a point must be triangulated from this many cameras
  double flag_ratio = 2.0;   // flag a camera whose median residual exceeds ratio x the rig's
  double min_flag_px = 3.0;  // ... and this many pixels
  int frame_step = 1;        // check every n-th frame
  Status Validate() const;   // messages name the fields
};

struct CameraCheck {
  explicit CameraCheck(std::string name = "") : name(std::move(name)) {}
  std::string name;
  int64_t residuals = 0;  // reprojections measured
  double median_px = 0, p90_px = 0;
  bool flagged = false;
  // Frames (capture numbering) whose median residual in this camera is above the
  // threshold, as [first, last] ranges; only for a flagged camera.
  std::vector<std::pair<int64_t, int64_t>> off_frames;
};

struct CalibrationCheckSummary {
  std::string calibration;           // the file checked
  std::string result;                // the result folder whose points were used ("" = none)
  int64_t frames = 0;                // frames looked at
  double rig_median_px = 0;          // median of the cameras' medians
  double threshold_px = 0;           // max(min_flag_px, flag_ratio x rig_median_px)
  std::vector<CameraCheck> cameras;  // in the capture's camera order
  std::vector<std::string> flagged;  // names of the flagged cameras
  Json ToJson() const;
};

// Errors: the capture, labels or calibration cannot be read (messages name the file), a
// camera is not in the calibration, no keypoint is seen by enough cameras. With label
// views, "frames" is 1 and off_frames stays empty.
StatusOr<CalibrationCheckSummary> CheckCalibration(const CalibrationCheckOptions& options,
                                                   Progress& progress = NoProgress());

}  // namespace arco::calibrate
