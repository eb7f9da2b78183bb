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
#include "arco/pipeline/result_folder.h"
#include "arco/pipeline/summaries.h"
#include "arco/track/monocular_lift.h"
#include "arco/util/json_io.h"
#include "arco/util/npy.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"

namespace arco::pipeline {

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

// What the stage made: the record that ResultFolder writes into triangulation/ and the
// values the later stages of `arco run` take without reading them back.
struct TriangulateStageResult {
  TriangulateStageSummary summary;  // removed_stages: filled when written
  NpyArray<double> points3d;        // (F, P, 3) filtered, world units (triangulation/points3d.npy)
  SequenceTriangulation raw;        // before the filters (points3d_raw.npy and the masks)
  TriangulationRecord record;       // result.json's header and entry
};

// Triangulates every frame of an opened capture (capture_context.h: its calibration,
// view_to_camera, 2D keypoints (read here when null) and fingerprints) and filters; writes
// nothing (WriteTriangulation does). options.capture_dir is not read: the capture is.
// Progress: the total is the frame count, advanced per frame from worker threads.
// Precondition: options.Validate() is ok and its filters suit the capture
// (CheckTriangulationFilters, capture_checks.h): RunCapture checks both once, before its
// first stage; not checked here.
StatusOr<TriangulateStageResult> RunTriangulateStage(const TriangulateStageOptions& options,
                                                     const CaptureContext& capture,
                                                     Progress& progress = NoProgress());
// Writes the stage into `result` (ResultFolder::WriteTriangulation, which starts result.json
// anew) and puts the later stages that it removed into stage->summary.removed_stages;
// stage->raw is released (no later stage reads it).
Status WriteTriangulation(const ResultFolder& result,
                          const CaptureContext& capture,
                          TriangulateStageResult* stage);

// `arco triangulate CAPTURE`: validates the options, opens options.capture_dir (no
// instrument needed; the filters checked against it), runs the stage on it and writes it
// into options.result_dir.
StatusOr<TriangulateStageSummary> RunTriangulateStage(const TriangulateStageOptions& options,
                                                      Progress& progress = NoProgress());

}  // namespace arco::pipeline
