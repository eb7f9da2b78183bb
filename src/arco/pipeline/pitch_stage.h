// Stage 4: the pitch of the capture's audio at the video frames (audio/pitch_tracker.h)
// and its notes (audio/notes.h), which ResultFolder writes as pitch.csv and notes.csv into
// RESULT_DIR itself (pipeline/result_folder.h). With double_stops also up to two simultaneous notes
// per video frame (audio/double_stops.h, a second pass over the audio) into double_stops.csv, which
// the refinement reads (refine_stage.h, AddDoubleStops) in `arco run` and in `arco refine` alike.
// Without audio in the capture the stage does nothing and says so in a warning.
#pragma once

#include <string>

#include "arco/pipeline/capture_context.h"
#include "arco/pipeline/result_folder.h"
#include "arco/pipeline/summaries.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"

namespace arco::pipeline {

// No result_dir: the stage reads no result folder and writes nothing (its caller writes).
struct PitchStageOptions {
  bool double_stops = false;  // `arco run --double-stops`
  Status Validate() const;    // nothing to check yet; kept so every stage has one
};

// Progress: a total of 1000, advanced as the audio is read. Returns the stage's record
// (record.summary: the stage's summary), which ResultFolder::WritePitch writes; without
// audio only the summary (summary.ran false: nothing to write). Reads no result folder.
// The tracker's options are `arco pitch --capture`'s (PitchTrackerOptionsFor): one way to
// pitch a capture. Precondition: options.Validate() is ok (RunCapture validates the run's
// options once at its entry); not checked here.
StatusOr<PitchRecord> RunPitchStage(const PitchStageOptions& options,
                                    const CaptureContext& capture,
                                    Progress& progress = NoProgress());

}  // namespace arco::pipeline
