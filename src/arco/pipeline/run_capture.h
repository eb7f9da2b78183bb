// `arco run CAPTURE -o RESULT` as a library call: every stage, in order, each taking the
// records of the earlier ones as made and writing its own into the result folder
// (pipeline/result_folder.h) through the run's one ResultFolder (nothing is read back):
//   1. triangulate  triangulation/   pipeline/triangulate_stage.h
//   2. instrument   instrument/      pipeline/instrument_stage.h
//   3. hands        hand/            pipeline/hand_stage.h
//   4. pitch        pitch.csv, notes.csv  pipeline/pitch_stage.h (skipped without audio)
//   5. refine       vision/ paper/ arco/  pipeline/refine_stage.h (paper and arco need
//                                    the pitch)
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "arco/pipeline/capture_context.h"
#include "arco/pipeline/hand_stage.h"
#include "arco/pipeline/instrument_stage.h"
#include "arco/pipeline/pitch_stage.h"
#include "arco/pipeline/refine_stage.h"
#include "arco/pipeline/result_folder.h"
#include "arco/pipeline/summaries.h"
#include "arco/pipeline/triangulate_stage.h"
#include "arco/util/output_set.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"
#include "arco/util/validated.h"

namespace arco::pipeline {

struct RunOptions {
  std::string capture_dir;
  std::string result_dir;
  // The stages' own options; their capture_dir / result_dir / num_threads are set from the
  // fields above and below when the run starts.
  TriangulateStageOptions triangulate;
  InstrumentStageOptions instrument;
  HandStageOptions hands;
  PitchStageOptions pitch;
  refine::RefineOptions refine;  // mode ignored: vision, paper and arco are all written
  int num_threads = 0;           // 0 = all cores; results do not depend on it
  // Replace an existing non-empty result_dir (only one holding result.json). The whole
  // result folder is written under a hidden temporary name and moved in at the end.
  bool overwrite = false;
  // Double stops (issue 27): a second pass of the polyphonic tracker over the audio
  // (audio/double_stops.h); arco refines the lower note as the first voice and the upper
  // one as contacts_2.csv (refine/double_stop_refine.h). Off: the outputs are as before.
  bool double_stops = false;

  // Every nested option (as the stages will receive them).
  Status Validate() const;
  // The stages' options with the run's folders and thread count filled in.
  TriangulateStageOptions ForTriangulate() const;
  InstrumentStageOptions ForInstrument() const;
  HandStageOptions ForHands() const;
  PitchStageOptions ForPitch() const;
  RefineStageOptions ForRefine(refine::RefineMode mode) const;
  // When result_dir may be replaced (util/output_set.h).
  FolderReplace Replace() const;
};

struct StageTiming {
  std::string name;    // triangulate, instrument, hands, pitch (when it ran), refine
  double seconds = 0;  // wall time (informational, not in results)
  // Ran on a thread of its own beside the stages before it (the pitch stage with more than
  // one thread): its seconds overlap theirs and are not part of the run's total.
  bool beside = false;
};

struct RunSummary {
  TriangulateStageSummary triangulate;
  InstrumentStageSummary instrument;
  HandStageSummary hands;
  PitchStageSummary pitch;
  std::vector<refine::RefineSummary> methods;  // vision, then paper and arco with audio
  std::vector<StageTiming> timings;            // in the order the stages ran
  std::vector<std::string> warnings;           // of all stages, in order
};

// Every option as the stages receive them (result.json "options", docs/formats.md):
// num_threads, overwrite and "triangulate", "instrument", "hands", "refine" (the refine
// options of the arco method; paper and vision record theirs in their stage entries).
// The folders are not repeated (result.json has "capture"; the result is the folder).
Json ToJson(const RunOptions& options);

inline constexpr int kRunStages = 5;

// The records of a run's stages as they made them (result_folder.h), which the result
// folder's writers take.
struct RunRecords {
  TriangulateStageResult triangulation;
  InstrumentRecord instrument;
  HandRecord hand;
  PitchRecord pitch;                  // summary.ran false: no audio (nothing written)
  std::vector<MethodRecord> methods;  // vision, then paper and arco when the pitch ran
};

// Stage 5 of the run: vision, then paper and arco when the pitch stage ran, refined from
// the records of stages 1-4 (methods ignored), the hands, pitch and notes passed through
// their files' encodings in memory, so that the run refines exactly what `arco refine`
// reads (MakeRefineInputs). Messages name the files of options.result_dir. Precondition:
// options validated. Progress: a total of the methods, advanced per method. `made`, when
// given, is called with each method's record as it is made (`arco run` writes it then);
// the record stays at that address in the returned vector.
StatusOr<std::vector<MethodRecord>> RunRefineMethods(
    const RunOptions& options,
    const CaptureContext& capture,
    const RunRecords& records,
    Progress& progress = NoProgress(),
    const std::function<void(const MethodRecord&)>& made = nullptr);

// Writes every record into `result` in the stages' order (the pitch only when it ran);
// records->triangulation.raw is released (WriteTriangulation).
Status WriteRunRecords(const ResultFolder& result,
                       const CaptureContext& capture,
                       RunRecords* records);

// options.result_dir written from `records` as `arco run` writes it: one folder moved into
// place when complete (replaced only with options.overwrite), result.json's "options"
// from `options`. With the records of the stages run one by one on OpenRunCapture's
// context (the Python bindings' arco.write_result), the folder is `arco run`'s, byte for
// byte.
Status WriteRunResult(const Validated<RunOptions>& options,
                      const CaptureContext& capture,
                      RunRecords records);

// The capture opened with every input the stages read, checked as PreflightRun checks them
// but for the result folder (nothing is written): for running the stages one by one.
StatusOr<CaptureContext> OpenRunCapture(const Validated<RunOptions>& options);

// Fail early: every input `arco run` will need is checked before its first stage
// (pipeline/capture_checks.h), so a bad capture costs milliseconds, not the triangulation
// and hand fitting before it, and leaves no result folder (docs/architecture.md,
// "Validation rules").
// Every check of `arco run`, in the order a user fixes them: options, the result folder
// (writable; replaceable only with --overwrite), capture.json and its instrument and
// layout (OpenCapture), the calibration and cameras, keypoints2d.npy (dtype and shape,
// from its header; the instrument's string ends present), the filters, the audio and its offset.
// Returns the opened capture.
StatusOr<CaptureContext> PreflightRun(const RunOptions& options);
// The same on a capture already opened (OpenCapture(options.capture_dir), e.g. by `arco
// run` to list its files before anything is written): capture.json is not read again.
// Throws std::invalid_argument when `opened` is another folder's (a caller bug).
StatusOr<CaptureContext> PreflightRun(const RunOptions& options, CaptureContext opened);

// The options are validated once, here at the entry (Validated<RunOptions>::Check, the
// first of PreflightRun's checks); the stages take them as validated and do not check
// them again. Progress: StartStage(i, 5, name) for each stage, then that stage's
// SetTotal / Advance.
StatusOr<RunSummary> RunCapture(const RunOptions& options, Progress& progress = NoProgress());
// The same with options already validated (`arco run` checks them when it parses its
// command line, and hands them on): opens the capture.
StatusOr<RunSummary> RunCapture(const Validated<RunOptions>& options,
                                Progress& progress = NoProgress());
// The same on a capture already opened (OpenCapture(options->capture_dir), e.g. by `arco
// run` to list its files): PreflightRun's checks after the options then run on it.
StatusOr<RunSummary> RunCapture(const Validated<RunOptions>& options,
                                CaptureContext opened,
                                Progress& progress = NoProgress());

}  // namespace arco::pipeline
