// Importer (and exporter, for round trips) of SPD's per-frame 2D keypoint folders
// (DOMAIN.md section 3; the dataset authors' pipeline):
//   HUMAN_DIR/<serial>/<n>.json        [[x, y, score] x 133] (DWPose, COCO-WholeBody),
//                                      or the full 142 (cello) / 140 (violin) rows
//   INSTRUMENT_DIR/<serial>/<n>.json   [[x, y, score] x 9] (cello) / x 7 (violin)
// Files hold bare NaN tokens for missing values. <n> is the camera's own 1-based
// frame number: global frame g is file g - (drops of that camera before g), where the
// drops come from the summary's FrameDropIDLog {serial: [global frames] or null};
// a camera has no file for a frame it dropped.
// Pixels are in the rotated SPD image, which the calibration uses.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "arco/util/npy.h"
#include "arco/util/status.h"

namespace arco {

// One per-frame file: an array of [x, y, score] rows (NaN allowed).
StatusOr<std::vector<Eigen::Vector3d>> ParseSpdFrame(const std::string& text,
                                                     const std::string& source);

// The parts of an SPD "<session>_summary.json" arco uses.
struct SpdSummary {
  int64_t start_frame = 0;                                  // "StartFrame", 0 when absent
  int64_t end_frame = 0;                                    // "EndFrame", 0 when absent
  std::map<std::string, std::vector<int64_t>> frame_drops;  // "FrameDropIDLog", sorted
};
StatusOr<SpdSummary> ParseSpdSummary(const std::string& text, const std::string& source);
StatusOr<SpdSummary> ReadSpdSummary(const std::string& path);

struct SpdImportOptions {
  std::string instrument = "cello";  // cello (9 instrument points) or violin (7)
  std::string human_dir;             // required
  std::string instrument_dir;        // optional; its rows replace the instrument part
  std::vector<std::string> serials;  // cameras, in view order
  int64_t frame_first = 1;           // global frame numbers, inclusive
  int64_t frame_last = 1;
  std::map<std::string, std::vector<int64_t>> frame_drops;
  bool require_all_files = false;  // false: a missing file leaves NaN
  Status Validate() const;
};

struct SpdImportReport {
  int64_t files_read = 0;
  int64_t files_missing = 0;   // expected but absent (NaN written)
  int64_t frames_dropped = 0;  // (camera, frame) pairs listed in FrameDropIDLog
};

// (frames, views, 142 or 140, 3) in the spd_cello / spd_violin layout.
StatusOr<NpyArray<double>> ImportSpdKeypoints(const SpdImportOptions& options,
                                              SpdImportReport* report = nullptr);

// Writes (frames, views, 142 / 140, 3) keypoints as SPD folders (the inverse of
// ImportSpdKeypoints with the same options; dropped frames get no file). NaN is
// written as a bare NaN token, as SPD does.
Status ExportSpdKeypoints(const SpdImportOptions& options, const NpyArray<double>& keypoints2d);

}  // namespace arco
