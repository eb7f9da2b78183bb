// Stage 1: a capture folder's 2D keypoints -> 3D keypoints of every frame, filtered, in
// RESULT_DIR/triangulation/ (pipeline/result_folder.h). Also `arco triangulate CAPTURE`.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "arco/mocap/temporal_filter.h"
#include "arco/mocap/triangulate_sequence.h"
#include "arco/pipeline/summaries.h"
#include "arco/util/json_io.h"
#include "arco/util/npy.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"

namespace arco::pipeline {

struct TriangulateStageOptions {
  std::string capture_dir;
  std::string result_dir;
  SequenceTriangulationOptions triangulation;
  // (group, filter) applied in order; later entries win for points in several groups.
  // Groups and filter rates are checked against the capture when the stage runs.
  std::vector<std::pair<std::string, TemporalFilterOptions>> filters;
  Status Validate() const;
};

// The options as recorded in result.json: the point options and "filters" [{group,
// filter, max_gap_frames}].
Json ToJson(const TriangulateStageOptions& options);

// Reads CAPTURE_DIR, triangulates every frame, filters, writes RESULT_DIR. Progress: the
// total is the frame count, advanced per frame from worker threads. keypoints2d: the
// capture's keypoints2d.npy already read (`arco run` reads it once); null: read here.
StatusOr<TriangulateStageSummary> RunTriangulateStage(
    const TriangulateStageOptions& options,
    Progress& progress = NoProgress(),
    std::shared_ptr<const NpyArray<double>> keypoints2d = nullptr);

}  // namespace arco::pipeline
