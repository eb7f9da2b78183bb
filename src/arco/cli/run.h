// The work behind `arco run` and `arco refine` (run_command.cc and refine_command.cc parse
// argv into these options; tests call these functions directly).
//
// `arco run CAPTURE -o RESULT`, stage by stage, each written to RESULT (docs/formats.md):
//   1. triangulate   triangulation/  (TriangulateCapture, cli/triangulate.h)
//   2. instrument    instrument/     rigid template over the clip, per-frame poses smoothed
//                                    (instrument/template_fit.h, pose_smoothing.h); the
//                                    metric scale; strings.npy (F, 4, 2, 3) and the placed
//                                    instrument keypoints keypoints.npy, both in mm
//   3. hands         hand/           per-performer bone lengths, then the multi-view hand
//                                    model fit of the left hand (hand/fit.h) in chunks of
//                                    frames solved in parallel; hand_params.npy (F, 26)
//   4. pitch         pitch.csv, notes.csv in RESULT itself: pitch at the video frames
//                                    (audio/pitch_tracker.h) and the audio's notes
//   5. refine        vision/ paper/ arco/ (refine/method_result.h)
// `arco refine RESULT --mode M` re-runs stage 5 for one method from the files of stages
// 1-4, exactly as `arco run` does.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "arco/hand/bone_lengths.h"
#include "arco/hand/fit.h"
#include "arco/instrument/pose_smoothing.h"
#include "arco/instrument/template_fit.h"
#include "arco/mocap/temporal_filter.h"
#include "arco/mocap/triangulate_sequence.h"
#include "arco/refine/refine.h"
#include "arco/util/status.h"

namespace arco::cli {

struct RunOptions {
  std::string capture_dir;
  std::string result_dir;
  SequenceTriangulationOptions triangulation;
  std::vector<std::pair<std::string, TemporalFilterOptions>> filters;  // (group, filter)
  InstrumentFitOptions instrument;
  // Gaussian pose smoothing; frames without a pose within 15 frames of posed frames on both
  // sides get one.
  PoseSmoothingOptions smoothing = [] {
    PoseSmoothingOptions o;
    o.max_fill_gap_frames = 15;
    return o;
  }();
  hand::BoneLengthOptions bones;
  hand::HandFitOptions hand_fit;
  // The hand fit carries a temporal prior from frame to frame; the clip is cut into chunks
  // of this many frames that are fitted in parallel (each starts from its own 3D keypoints),
  // so results do not depend on the thread count.
  int hand_chunk_frames = 30;
  refine::RefineOptions refine;  // mode ignored: vision, paper and arco are all written
  int num_threads = 0;           // 0 = all cores
};

// Stage progress for the terminal: on_stage(index, count, name) when a stage starts;
// on_total(n) when it knows its amount of work, on_advance(k) as work is done (from
// worker threads; must be thread-safe).
struct RunProgress {
  std::function<void(int index, int count, const std::string& name)> on_stage;
  std::function<void(int64_t total)> on_total;
  std::function<void(int64_t done)> on_advance;
};

struct StageReport {
  std::string name;
  double seconds = 0;   // wall time (informational, not in results)
  std::string summary;  // one line for the terminal
};

struct RunSummary {
  std::vector<StageReport> stages;
  std::vector<std::string> warnings;
  std::vector<refine::RefineSummary> methods;  // vision, then paper and arco when audio exists
};

StatusOr<RunSummary> RunCapture(const RunOptions& options, const RunProgress& progress = {});

struct RefineDirOptions {
  std::string result_dir;
  refine::RefineOptions refine;  // refine.mode picks the method
};

// Re-runs the refinement of one method on a result folder written by `arco run`.
StatusOr<refine::RefineSummary> RefineResultDir(const RefineDirOptions& options);

// One line per method for the terminal: pressed/open/rest/uncertain frames, corrected
// frames and the fingertip-to-contact distance before and after.
std::string FormatRefineSummary(const refine::RefineSummary& summary);

}  // namespace arco::cli
