// The work behind `arco triangulate` (triangulate_command.cc parses argv into these
// options; tests call these functions directly).
//
// Two modes:
//  - labelled views: one labelme file per camera -> one JSON file of 3D points;
//  - a capture folder (docs/formats.md) -> a result folder with whole sequences.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "arco/mocap/capture.h"
#include "arco/mocap/labelme.h"
#include "arco/mocap/temporal_filter.h"
#include "arco/mocap/triangulate_point.h"
#include "arco/util/json_io.h"
#include "arco/util/status.h"

namespace arco::cli {

struct LabelViewsOptions {
  std::string calibration;  // any calibration format LoadCalibration reads
  // (camera name or serial, labelme file) per view.
  std::vector<std::pair<std::string, std::string>> views;
  TriangulationOptions triangulation;
  PixelOrigin label_origin = PixelOrigin::kCorner;  // labelme's own convention
  bool ignore_distortion = false;  // triangulate as if the lenses had no distortion
  // When > 0, the mean of the two string sides (nut-bridge) is taken to be this long
  // and lengths are also reported in mm (display only; SPD assumes 695 mm for cello).
  double reference_string_length_mm = 0;
};

// Triangulates every label seen in at least two views. The JSON holds "units",
// "rms_reprojection_px" (over all inlier observations), "points" [{"name", "xyz",
// "inlier_views", "rms_reprojection_px", "num_views", "reprojection_px"}],
// "not_triangulated", and "lengths" (string sides nut_l-bridge_l / nut_r-bridge_r and
// their difference in percent, when those labels exist). Errors name the file: bad
// calibration or label file, a camera missing from the calibration, a camera used
// twice, fewer than two views, an image size that differs from the camera's, or no
// label triangulated at all.
StatusOr<Json> TriangulateLabelViews(const LabelViewsOptions& options);

// Human-readable report of TriangulateLabelViews' JSON (for the terminal and the demo).
std::string FormatLabelViewsReport(const Json& result);

struct CaptureOptions {
  std::string capture_dir;
  std::string result_dir;
  SequenceTriangulationOptions triangulation;
  // (group, filter) applied in order; later entries win for points in several groups.
  std::vector<std::pair<std::string, TemporalFilterOptions>> filters;
};

struct CaptureRunSummary {
  SequenceTriangulationSummary triangulation;
  std::string units;
  int64_t views = 0;
  int64_t keypoints = 0;
};

// Reads CAPTURE_DIR, triangulates every frame, filters, writes RESULT_DIR (see
// mocap/capture.h). `progress(frames_done)` is called from worker threads.
StatusOr<CaptureRunSummary> TriangulateCapture(const CaptureOptions& options,
                                               const std::function<void(int64_t)>& progress = {},
                                               const std::function<void(int64_t)>& on_start = {});

}  // namespace arco::cli
