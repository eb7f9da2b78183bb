// Triangulation of whole sequences: every keypoint of every frame, frames in
// parallel (util/parallel.h: each frame writes only its own slots, so results are
// identical for any thread count).
//
// Array conventions (docs/formats.md): 2D keypoints are (frames, views, points, 3)
// holding [x_px, y_px, score], NaN for missing; 3D points are (frames, points, 3) in
// rig units, NaN where not triangulated.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "arco/camera/rig.h"
#include "arco/mocap/triangulate_point.h"
#include "arco/util/json_io.h"
#include "arco/util/npy.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"

namespace arco {

struct SequenceTriangulationOptions {
  TriangulationOptions point;
  int num_threads = 0;  // 0 = all cores; results do not depend on it
  Status Validate() const;
};

struct SequenceTriangulation {
  NpyArray<double> points3d;            // (F, P, 3), NaN when not triangulated
  NpyArray<float> rms_reprojection_px;  // (F, P), NaN when not triangulated
  NpyArray<int32_t> num_inliers;        // (F, P) inlier views, 0 when not triangulated
  NpyArray<int32_t> num_views;          // (F, P) usable views (finite, score >= min_score)
  NpyArray<uint8_t> inlier_mask;        // (F, P, V) 1 where view v is an inlier
  // (F, P) where each point's depth came from when the capture has one camera
  // (track/monocular_lift.h LiftDepth; triangulation/depth_source.npy); empty when the
  // points were triangulated from several views.
  NpyArray<uint8_t> depth_source;
  // (F) one camera only: how far the instrument's depth may be off, mm
  // (track/monocular_lift.h; triangulation/depth_sigma_mm.npy).
  NpyArray<float> depth_sigma_mm;
};

struct SequenceTriangulationSummary {
  int64_t frames = 0;
  int64_t points = 0;                     // frames x keypoints
  int64_t triangulated = 0;               // points with a 3D position
  double median_rms_reprojection_px = 0;  // over triangulated points (NaN when none)
  double mean_inliers = 0;                // mean inlier views per triangulated point
  // One camera only (a lift, not a triangulation): the median over frames of the
  // instrument's depth uncertainty (SequenceTriangulation::depth_sigma_mm), NaN when none.
  bool one_view = false;
  double median_depth_sigma_mm = std::numeric_limits<double>::quiet_NaN();
};

// `keypoints2d` is (F, V, P, 3); `view_to_camera[v]` is the rig camera of view v.
// `progress`, when set, is advanced by the number of frames just finished (from worker
// threads). Errors: shape mismatches and view indices
// outside the rig are returned as a Status naming `source`.
StatusOr<SequenceTriangulation> TriangulateSequence(
    const Rig& rig,
    const std::vector<int>& view_to_camera,
    const NpyArray<double>& keypoints2d,
    const SequenceTriangulationOptions& options,
    Progress* progress = nullptr,
    const std::string& source = "keypoints2d");

SequenceTriangulationSummary Summarize(const SequenceTriangulation& result);

// {frames, points, triangulated, median_rms_reprojection_px (null when NaN), mean_inliers}.
Json ToJson(const SequenceTriangulationSummary& summary);

}  // namespace arco
