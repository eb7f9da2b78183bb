// Stage 1: a capture folder's 2D keypoints -> 3D keypoints of every frame, filtered, in
// RESULT_DIR/triangulation/ (pipeline/result_folder.h). Also `arco triangulate CAPTURE`.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "arco/mocap/temporal_filter.h"
#include "arco/mocap/triangulate_sequence.h"
#include "arco/pipeline/capture_context.h"
#include "arco/pipeline/summaries.h"
#include "arco/track/monocular_lift.h"
#include "arco/util/json_io.h"
#include "arco/util/npy.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"

namespace arco::pipeline {

class ResultFolder;

struct TriangulateStageOptions {
  std::string capture_dir;
  std::string result_dir;
  SequenceTriangulationOptions triangulation;
  // A capture of one camera is lifted from its view instead (track/monocular_lift.h).
  track::MonocularLiftOptions one_view;
  // (group, filter) applied in order; later entries win for points in several groups.
  // Groups and filter rates are checked against the capture when the stage runs.
  std::vector<std::pair<std::string, TemporalFilterOptions>> filters;
  Status Validate() const;
};

// The options as recorded in result.json: the point options and "filters" [{group,
// filter, max_gap_frames}].
Json ToJson(const TriangulateStageOptions& options);

// What the stage made, as the later stages of `arco run` take it: the values
// triangulation/ holds, without reading them back.
struct TriangulateStageResult {
  TriangulateStageSummary summary;
  NpyArray<double> points3d;  // (F, P, 3) filtered, world units (triangulation/points3d.npy)
};

// Triangulates every frame of an opened capture (capture_context.h: its calibration,
// view_to_camera, 2D keypoints (read here when null) and fingerprints), filters, writes
// RESULT_DIR. options.capture_dir is not read: the capture is. Progress: the total is the
// frame count, advanced per frame from worker threads.
StatusOr<TriangulateStageResult> RunTriangulateStage(const TriangulateStageOptions& options,
                                                     const CaptureContext& capture,
                                                     Progress& progress = NoProgress());
// The same into `result` (options.result_dir's folder, result_folder.h: `arco run` hands
// every stage its one ResultFolder).
StatusOr<TriangulateStageResult> RunTriangulateStage(const TriangulateStageOptions& options,
                                                     const CaptureContext& capture,
                                                     const ResultFolder& result,
                                                     Progress& progress = NoProgress());

// `arco triangulate CAPTURE`: opens options.capture_dir (no instrument needed) and runs
// the stage on it.
StatusOr<TriangulateStageSummary> RunTriangulateStage(const TriangulateStageOptions& options,
                                                      Progress& progress = NoProgress());

}  // namespace arco::pipeline
