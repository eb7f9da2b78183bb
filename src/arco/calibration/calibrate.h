// `arco calibrate`: board videos or image folders -> a rig calibration and its report.
// Detection per camera (board_detection.h), then CalibrateRig (rig_calibration.h); the
// calibration (any format SaveCalibration writes, by extension) and the report
// (CALIBRATION minus its extension + ".report.json") are written together through one
// OutputSet: nothing is written on an error.
#pragma once

#include <string>
#include <vector>

#include "arco/calibration/board_detection.h"
#include "arco/calibration/rig_calibration.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"

namespace arco::calibration {

struct CalibrateInput {
  std::string camera;  // name the camera gets in the calibration
  std::string path;    // a video, a folder of images or one image
};

struct CalibrateOptions {
  std::string board;  // the spec text (board.h)
  std::vector<CalibrateInput> inputs;
  std::string intrinsics;  // optional calibration file giving intrinsics by camera name
  std::string output;      // the calibration file to write
  BoardDetectionOptions detection;
  RigCalibrationOptions calibration;
  int num_threads = 0;      // cameras detected in parallel (0 = all cores)
  Status Validate() const;  // the board spec, the inputs' names, the nested options
};

// "CAMERA=PATH" -> input; errors quote the text.
StatusOr<CalibrateInput> ParseCalibrateInput(const std::string& text);

// "rig.json" -> "rig.report.json", "out/rig" -> "out/rig.report.json".
std::string ReportPath(const std::string& calibration_path);

struct CalibrateResult {
  RigCalibration calibration;
  std::string report_path;
  std::vector<CameraBoardViews> detections;
};

// Checks the outputs' locations and reads --intrinsics before any detection; writes both
// files only when everything succeeded.
StatusOr<CalibrateResult> RunCalibrate(const CalibrateOptions& options,
                                       Progress& progress = NoProgress());

}  // namespace arco::calibration
