// Labelled views triangulated: one labelme file per camera -> 3D points as JSON
// (`arco triangulate --calibration CAL --view CAMERA=LABELS ...`; the truth of
// `arco eval` on real recordings). A capture folder's sequences are stage 1 of the
// pipeline (pipeline/triangulate_stage.h).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "arco/mocap/labelme.h"
#include "arco/mocap/triangulate_point.h"
#include "arco/util/json_io.h"
#include "arco/util/status.h"

namespace arco::capture {

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

}  // namespace arco::capture
