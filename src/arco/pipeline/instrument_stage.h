// Stage 2: the instrument. A rigid template fitted over the whole clip to the triangulated
// instrument keypoints (instrument/template_fit.h), per-frame poses smoothed and short gaps
// filled (instrument/pose_smoothing.h), the world's metric scale; writes
// RESULT_DIR/instrument/ strings.npy (F, 4, 2, 3) and the placed template keypoints.npy,
// both in mm (pipeline/result_folder.h).
#pragma once

#include <string>
#include <vector>

#include "arco/instrument/pose_smoothing.h"
#include "arco/instrument/template_fit.h"
#include "arco/pipeline/capture_context.h"
#include "arco/pipeline/result_folder.h"
#include "arco/pipeline/summaries.h"
#include "arco/pipeline/triangulate_stage.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"

namespace arco::pipeline {

struct InstrumentStageOptions {
  std::string result_dir;  // holds the triangulation
  InstrumentFitOptions fit;
  // Gaussian pose smoothing; frames without a pose within 15 frames of posed frames on both
  // sides get one, and so do the take's first and last frames within 5 of a posed frame
  // (a sixth of a second at 30 fps: on the real take seen by one camera, the first 1-3
  // frames of 17 of 30 captures had too few points; docs/accuracy.md, "The take's first
  // frames").
  PoseSmoothingOptions smoothing = [] {
    PoseSmoothingOptions o;
    o.max_fill_gap_frames = 15;
    o.max_end_hold_frames = 5;
    return o;
  }();
  // The kernel's width chosen per capture among these (frames, each > 0; empty: always
  // smoothing.sigma_frames) by leave-one-out cross-validation of the strings' ends
  // (LeaveOneOutSigmaFrames): a held instrument seen by few cameras is smoothed over
  // longer, a moving one or one seen by many as before. On the real take seen by two
  // cameras it chose 7-20 frames and the instrument came 5.2 -> 4.4 mm from SPD's, the
  // contact 5.4 -> 4.9 mm; with 4 or 19 cameras and on arco's simulator it chose 2 (docs/
  // accuracy.md, "The instrument held still: its smoothing chosen per capture").
  std::vector<double> smoothing_candidates_frames = {2, 3, 5, 7, 10, 15, 20};
  int num_threads = 0;  // 0 = all cores; results do not depend on it
  Status Validate() const;
};

// Every option but result_dir, as result.json records it ("options"."instrument").
Json ToJson(const InstrumentStageOptions& options);

// Fits the instrument to the triangulation made from `capture` (as `arco run` holds it,
// not read back); writes nothing: the record is what ResultFolder::WriteInstrument writes
// into instrument/ (record.summary: the stage's summary). Precondition: options.Validate()
// is ok (RunCapture validates the run's options once at its entry; a caller of the stage
// alone validates first); not checked here.
StatusOr<InstrumentRecord> RunInstrumentStage(const InstrumentStageOptions& options,
                                              const CaptureContext& capture,
                                              const TriangulateStageResult& triangulation,
                                              Progress& progress = NoProgress());
// The same on the triangulation in options.result_dir, which must come from `capture`,
// written into it; this entry validates the options.
StatusOr<InstrumentStageSummary> RunInstrumentStage(const InstrumentStageOptions& options,
                                                    const CaptureContext& capture,
                                                    Progress& progress = NoProgress());

}  // namespace arco::pipeline
