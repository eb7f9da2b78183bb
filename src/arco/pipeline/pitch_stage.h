// Stage 4: the pitch of the capture's audio at the video frames (audio/pitch_tracker.h)
// and its notes (audio/notes.h); writes pitch.csv and notes.csv into RESULT_DIR itself
// (pipeline/result_folder.h). Without audio in the capture the stage does nothing and
// says so in a warning.
#pragma once

#include <string>

#include "arco/pipeline/capture_context.h"
#include "arco/pipeline/summaries.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"

namespace arco::pipeline {

struct PitchStageOptions {
  std::string result_dir;
  Status Validate() const;
};

// Progress: a total of 1000, advanced as the audio is read.
StatusOr<PitchStageSummary> RunPitchStage(const PitchStageOptions& options,
                                          const CaptureContext& capture,
                                          Progress& progress = NoProgress());

}  // namespace arco::pipeline
