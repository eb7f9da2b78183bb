// SPD per-frame 2D keypoint folders (mocap/spd_import.h) -> an arco capture folder
// (docs/formats.md) that the pipeline reads (`arco import-spd`).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "arco/mocap/spd_import.h"
#include "arco/util/status.h"

namespace arco::capture {

struct ImportSpdOptions {
  std::string calibration;           // copied into the capture; gives camera names and serials
  std::string summary;               // optional SESSION_summary.json (frame range, FrameDropIDLog)
  std::string human_dir;             // HUMAN_DIR/<serial>/<n>.json
  std::string instrument_dir;        // optional INSTRUMENT_DIR/<serial>/<n>.json
  std::string instrument = "cello";  // cello or violin
  std::vector<std::string> serials;  // default: calibration cameras with a folder in human_dir
  int64_t frame_first = 0, frame_last = 0;  // 0 = from the summary's StartFrame / EndFrame
  double fps = 30.0;
  std::string audio;  // optional, copied
  double audio_offset_s = 0;
  std::string name;        // session name (default: the output folder's name)
  std::string output_dir;  // must not exist or be empty, unless `overwrite`
  bool overwrite = false;  // replace an existing capture (a folder with capture.json)
};

struct ImportSpdSummary {
  SpdImportReport files;
  int64_t frames = 0, views = 0, points = 0;
  // A keypoint folder of a camera the calibration lacks (not imported), one line each.
  std::vector<std::string> warnings;
};

// Writes OUTPUT_DIR/{capture.json, keypoints2d.npy, calibration file[, audio]}; built in
// a temporary folder and renamed into place, so nothing is left on error.
StatusOr<ImportSpdSummary> ImportSpdCapture(const ImportSpdOptions& options);

}  // namespace arco::capture
