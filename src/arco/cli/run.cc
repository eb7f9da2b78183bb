#include "arco/cli/run.h"

#include <chrono>
#include <cstdio>

#include "arco/cli/run_stages.h"
#include "arco/cli/triangulate.h"

namespace arco::cli {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

std::string FormatRefineSummary(const refine::RefineSummary& s) {
  char buf[512];
  if (s.mode == refine::RefineMode::kVision) {
    std::snprintf(buf,
                  sizeof(buf),
                  "vision: fitted hand on %d of %d frames (no audio)",
                  s.frames_with_hand,
                  s.frames);
    return buf;
  }
  std::snprintf(buf,
                sizeof(buf),
                "%s: %d pressed, %d open string, %d rest, %d uncertain of %d frames; %d notes; "
                "%d corrected, fingertip to contact %.1f -> %.2f mm; %d out of reach; %d limit "
                "violations",
                refine::RefineModeName(s.mode),
                s.pressed,
                s.open_string,
                s.rest,
                s.uncertain,
                s.frames,
                s.usable_notes,
                s.corrected_frames,
                s.mean_tip_distance_vision_mm,
                s.mean_tip_distance_refined_mm,
                s.rejected_out_of_reach,
                s.joint_limit_violations);
  return buf;
}

StatusOr<RunSummary> RunCapture(const RunOptions& options, const RunProgress& progress) {
  RunSummary summary;
  ARCO_RETURN_IF_ERROR(options.refine.Validate());
  ARCO_ASSIGN_OR_RETURN(internal::CaptureContext capture,
                        internal::OpenCapture(options.capture_dir));
  constexpr int kStages = 5;
  auto stage = [&](int index, const char* name) {
    if (progress.on_stage) progress.on_stage(index, kStages, name);
    return Clock::now();
  };

  // 1. Triangulation.
  auto start = stage(1, "triangulate");
  CaptureOptions t;
  t.capture_dir = options.capture_dir;
  t.result_dir = options.result_dir;
  t.triangulation = options.triangulation;
  t.triangulation.num_threads = options.num_threads;
  t.filters = options.filters;
  ARCO_ASSIGN_OR_RETURN(CaptureRunSummary tri,
                        TriangulateCapture(t, progress.on_advance, progress.on_total));
  char line[256];
  std::snprintf(line,
                sizeof(line),
                "%lld of %lld points, median reprojection %.2f px (units %s)",
                static_cast<long long>(tri.triangulation.triangulated),
                static_cast<long long>(tri.triangulation.points),
                tri.triangulation.median_rms_reprojection_px,
                tri.units.c_str());
  summary.stages.push_back({"triangulate", SecondsSince(start), line});

  // 2-4. Instrument, hands, pitch.
  start = stage(2, "instrument");
  ARCO_ASSIGN_OR_RETURN(StageReport instrument,
                        internal::RunInstrumentStage(options, capture, &summary.warnings));
  instrument.seconds = SecondsSince(start);
  summary.stages.push_back(instrument);
  start = stage(3, "hands");
  ARCO_ASSIGN_OR_RETURN(StageReport hands,
                        internal::RunHandStage(options, capture, progress, &summary.warnings));
  hands.seconds = SecondsSince(start);
  summary.stages.push_back(hands);
  start = stage(4, "pitch");
  ARCO_ASSIGN_OR_RETURN(StageReport pitch,
                        internal::RunPitchStage(options, capture, progress, &summary.warnings));
  if (!pitch.name.empty()) {
    pitch.seconds = SecondsSince(start);
    summary.stages.push_back(pitch);
  }

  // 5. Refinement: vision, paper, arco.
  start = stage(5, "refine");
  ARCO_ASSIGN_OR_RETURN(internal::RefineInputs inputs,
                        internal::LoadRefineInputs(options.result_dir));
  std::vector<refine::RefineMode> modes = {refine::RefineMode::kVision};
  if (inputs.has_pitch) {
    modes.push_back(refine::RefineMode::kPaper);
    modes.push_back(refine::RefineMode::kArco);
  }
  if (progress.on_total) progress.on_total(static_cast<int64_t>(modes.size()));
  std::string methods;
  for (refine::RefineMode mode : modes) {
    refine::RefineOptions ro = options.refine;
    ro.mode = mode;
    ro.num_threads = options.num_threads;
    ARCO_ASSIGN_OR_RETURN(refine::RefineSummary s,
                          internal::RefineAndWrite(options.result_dir, inputs, ro));
    summary.methods.push_back(s);
    methods += std::string(methods.empty() ? "" : ", ") + refine::RefineModeName(mode);
    if (progress.on_advance) progress.on_advance(1);
  }
  summary.stages.push_back({"refine", SecondsSince(start), "wrote " + methods});
  return summary;
}

StatusOr<refine::RefineSummary> RefineResultDir(const RefineDirOptions& options) {
  ARCO_RETURN_IF_ERROR(options.refine.Validate());
  ARCO_ASSIGN_OR_RETURN(internal::RefineInputs inputs,
                        internal::LoadRefineInputs(options.result_dir));
  return internal::RefineAndWrite(options.result_dir, inputs, options.refine);
}

}  // namespace arco::cli
