// Stage 5: the audio-guided refinement (refine/refine.h) of one method, read from and
// written to a result folder: RESULT_DIR/<method>/ (pipeline/result_folder.h). `arco run`
// writes vision, paper and arco; `arco refine` re-runs one method from the files of
// stages 1-4, so both refine exactly the same data.
#pragma once

#include <memory>
#include <string>

#include "arco/instrument/instrument_model.h"
#include "arco/refine/bowing.h"
#include "arco/refine/method_result.h"
#include "arco/refine/refine.h"
#include "arco/util/status.h"

namespace arco::pipeline {

struct RefineStageOptions {
  std::string result_dir;        // written by stages 1-4
  refine::RefineOptions refine;  // refine.mode picks the method
  refine::BowingOptions bowing;  // arco's bow arm (arco/bowing.csv)
  Status Validate() const;
};

// Everything the refinement needs, read from a result folder.
struct RefineInputs {
  std::shared_ptr<const InstrumentModel> instrument;
  refine::RefineInput input;  // input.pitch all unvoiced when the result has no pitch stage
  refine::SpdSources spd;
  bool has_pitch = false;
};
// Errors name the file: no hand or instrument stage, shapes that disagree.
StatusOr<RefineInputs> LoadRefineInputs(const std::string& result_dir);

// Refines one method (options.mode) and writes its folder; arco's also gets the bow arm
// (refine/bowing.h: bowing.csv, bowing_notes.csv). Errors: a method that needs audio on a
// result without a pitch stage.
StatusOr<refine::RefineSummary> RefineAndWrite(const std::string& result_dir,
                                               const RefineInputs& inputs,
                                               const refine::RefineOptions& options,
                                               const refine::BowingOptions& bowing = {});

// LoadRefineInputs + RefineAndWrite.
StatusOr<refine::RefineSummary> RunRefineStage(const RefineStageOptions& options);

}  // namespace arco::pipeline
