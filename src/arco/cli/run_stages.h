// Internal to `arco run` / `arco refine` (run.h): the stages between triangulation and
// refinement, and the loader that turns a result folder into the refinement's input.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "arco/cli/run.h"
#include "arco/mocap/capture.h"
#include "arco/refine/method_result.h"

namespace arco::cli::internal {

struct CaptureContext {
  std::string capture_dir;
  CaptureManifest manifest;
  KeypointLayout layout;
  std::shared_ptr<const InstrumentModel> instrument;
};

// Manifest, layout and instrument model of a capture. Errors: no instrument ("none").
StatusOr<CaptureContext> OpenCapture(const std::string& capture_dir);

// Stage 2-4 (run.h). Each reads what earlier stages wrote into the result folder.
StatusOr<StageReport> RunInstrumentStage(const RunOptions& options,
                                         const CaptureContext& capture,
                                         std::vector<std::string>* warnings);
StatusOr<StageReport> RunHandStage(const RunOptions& options,
                                   const CaptureContext& capture,
                                   const RunProgress& progress,
                                   std::vector<std::string>* warnings);
// Without audio in the capture: an empty report name and a warning.
StatusOr<StageReport> RunPitchStage(const RunOptions& options,
                                    const CaptureContext& capture,
                                    const RunProgress& progress,
                                    std::vector<std::string>* warnings);

// World units per mm recorded by the instrument stage in result.json.
StatusOr<double> WorldUnitsPerMm(const Json& manifest, const std::string& result_dir);

// Everything stage 5 needs, read from a result folder.
struct RefineInputs {
  std::shared_ptr<const InstrumentModel> instrument;
  refine::RefineInput input;  // input.pitch empty when the result has no pitch stage
  refine::SpdSources spd;
  bool has_pitch = false;
};
StatusOr<RefineInputs> LoadRefineInputs(const std::string& result_dir);

// Refines one method (options.mode) and writes its folder.
StatusOr<refine::RefineSummary> RefineAndWrite(const std::string& result_dir,
                                               const RefineInputs& inputs,
                                               const refine::RefineOptions& options);

}  // namespace arco::cli::internal
