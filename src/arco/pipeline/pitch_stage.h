// Stage 4: the pitch of the capture's audio at the video frames (audio/pitch_tracker.h)
// and its notes (audio/notes.h); writes pitch.csv and notes.csv into RESULT_DIR itself
// (pipeline/result_folder.h). With double_stops also up to two simultaneous notes per
// video frame (audio/double_stops.h, a second pass over the audio) into double_stops.csv,
// which the refinement reads (refine_stage.h, AddDoubleStops) in `arco run` and in
// `arco refine` alike. Without audio in the capture the stage does nothing and says so in
// a warning.
#pragma once

#include <string>

#include "arco/pipeline/capture_context.h"
#include "arco/pipeline/result_folder.h"
#include "arco/pipeline/summaries.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"

namespace arco::pipeline {

struct PitchStageOptions {
  std::string result_dir;
  bool double_stops = false;  // `arco run --double-stops`
  Status Validate() const;
};

// Progress: a total of 1000, advanced as the audio is read. Returns what it wrote
// (record.summary: the stage's summary; without audio only the summary, nothing written).
// The tracker's options are `arco pitch --capture`'s (PitchTrackerOptionsFor): one way to
// pitch a capture.
StatusOr<PitchRecord> RunPitchStage(const PitchStageOptions& options,
                                    const CaptureContext& capture,
                                    Progress& progress = NoProgress());
// The same into `result` (options.result_dir's folder: `arco run`'s one ResultFolder).
StatusOr<PitchRecord> RunPitchStage(const PitchStageOptions& options,
                                    const CaptureContext& capture,
                                    const ResultFolder& result,
                                    Progress& progress = NoProgress());

}  // namespace arco::pipeline
