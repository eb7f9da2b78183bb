// File-level calibration io: the one entry point the CLI and other layers use.
// Formats and conventions are described in camera/calibration_io.h; OpenCV
// cv::FileStorage YAML/XML lives here (OpenCV stays out of the core layers).
//
// Reading detects the format from the content: Metashape XML (<document>),
// OpenCV XML (<opencv_storage>), OpenCV YAML (%YAML), arco JSON (an object with
// "cameras"), otherwise SPD JSON.
#pragma once

#include <string>

#include "arco/camera/calibration_io.h"
#include "arco/util/status.h"

namespace arco::calibration {

StatusOr<Calibration> LoadCalibration(const std::string& path);

// Parses text whose format is detected as above; `source` names it in messages.
StatusOr<Calibration> ParseCalibration(const std::string& text, const std::string& source);
CalibrationFormat DetectCalibrationFormat(const std::string& text);

// Writes `rig` atomically (no partial file on failure). kUnknown picks the format
// from the extension: .yaml/.yml OpenCV YAML, .xml OpenCV XML, .json arco JSON.
// Metashape XML cannot be written.
Status SaveCalibration(const std::string& path,
                       const Rig& rig,
                       CalibrationFormat format = CalibrationFormat::kUnknown);

// "yaml", "opencv-xml", "spd", "arco" (as in `arco calibration convert --format`).
StatusOr<CalibrationFormat> CalibrationFormatFromFlag(const std::string& flag);

// OpenCV FileStorage layout written and read by arco:
//   format: "arco-calibration", units: "...", cameras: [ {name, serial,
//   image_width, image_height, camera_matrix (3x3), distortion_coefficients
//   (1x5: k1 k2 p1 p2 k3, OpenCV order), rotation (3x3, cam_from_world),
//   translation (3x1)} ]
StatusOr<Calibration> ParseOpenCvCalibration(const std::string& text, const std::string& source);
StatusOr<std::string> WriteOpenCvCalibration(const Rig& rig, bool yaml);

}  // namespace arco::calibration
