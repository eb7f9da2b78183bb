// Stage 3: the left hand. Per-performer bone lengths and palm from the triangulated hand
// (hand/bone_lengths.h, hand/palm_shape.h), then the multi-view hand model fit (hand/fit.h) of
// every frame; writes RESULT_DIR/hand/ hand_params.npy (F, 26), bone_lengths_mm.npy and
// rest_points_mm.npy, the fitted model (pipeline/result_folder.h).
#pragma once

#include <string>

#include "arco/hand/bone_lengths.h"
#include "arco/hand/fit.h"
#include "arco/hand/one_view_depth.h"
#include "arco/hand/palm_shape.h"
#include "arco/hand/pose_gaps.h"
#include "arco/pipeline/capture_context.h"
#include "arco/pipeline/result_folder.h"
#include "arco/pipeline/summaries.h"
#include "arco/pipeline/triangulate_stage.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"

namespace arco::pipeline {

struct HandStageOptions {
  std::string result_dir;  // holds the triangulation and the instrument (the metric scale)
  hand::BoneLengthOptions bones;
  hand::PalmShapeOptions palm;  // the performer's palm (after the bone lengths)
  hand::HandFitOptions fit;
  hand::OneViewDepthOptions one_view_depth;  // a one-camera capture's hand depth
  hand::PoseGapOptions gaps;                 // short gaps between fitted frames (hand/pose_gaps.h)
  // [0.5, 1): one camera: the bone lengths are this quantile of the lifted hand's
  // distances (bones.quantile; the lift's points are projections at the strings' depth).
  double one_view_bone_quantile = 0.75;
  // [0.5, 1): one camera: the same for the palm's bones (wrist to finger bases) and the
  // thumb's (bones.palm_quantile, bones.thumb_quantile; hand/bone_lengths.h says why).
  double one_view_palm_bone_quantile = 0.8;
  double one_view_thumb_bone_quantile = 0.7;
  // One camera: the palm's bones as one rigid piece, the average palm times one scale
  // (bones.palm_as_one, hand/bone_lengths.h says why; docs/accuracy.md, "One camera: the
  // palm as one piece"). false: each palm bone its own quantile (the former rule).
  bool one_view_palm_as_one = true;
  // The fit carries a temporal prior from frame to frame; the clip is cut into chunks of
  // this many frames that are fitted in parallel (each starts from its own 3D keypoints),
  // so results do not depend on the thread count.
  int chunk_frames = 30;
  int num_threads = 0;  // 0 = all cores
  Status Validate() const;
};

// Progress: the total is the frame count, advanced per finished chunk.
// Every option but result_dir, as result.json records it ("options"."hands").
Json ToJson(const HandStageOptions& options);

// Fits the hand of every frame to the triangulation and the instrument's scale made from
// `capture` (as `arco run` holds them, not read back), with the capture's 2D keypoints
// and calibration (capture_context.h); writes nothing: the record is what
// ResultFolder::WriteHand writes into hand/ (record.summary: the stage's summary).
// Precondition: options.Validate() is ok (RunCapture validates the run's options once at
// its entry; a caller of the stage alone validates first); not checked here.
StatusOr<HandRecord> RunHandStage(const HandStageOptions& options,
                                  const CaptureContext& capture,
                                  const TriangulateStageResult& triangulation,
                                  const InstrumentRecord& instrument,
                                  Progress& progress = NoProgress());
// The same on the stages in options.result_dir, which must come from `capture`, written
// into it; this entry validates the options.
StatusOr<HandStageSummary> RunHandStage(const HandStageOptions& options,
                                        const CaptureContext& capture,
                                        Progress& progress = NoProgress());

}  // namespace arco::pipeline
