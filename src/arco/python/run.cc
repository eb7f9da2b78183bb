// arco.run and arco.refine: `arco run CAPTURE -o RESULT` and `arco refine RESULT --mode M`
// as calls (pipeline/run_capture.h, pipeline/refine_stage.h), with the GIL released. Both
// write the same files as the commands (tests/test_run.py compares them byte for byte);
// read them back with arco.read_result. The stages' other options keep the library's
// defaults here (the commands' flags set them; docs/python.md says which are bound).
#include <filesystem>
#include <string>
#include <vector>

#include "arco/pipeline/refine_stage.h"
#include "arco/pipeline/run_capture.h"
#include "arco/python/bindings.h"
#include "arco/refine/contact_annotation.h"

namespace arco::python {
namespace {

// A method's summary as result.json records it, with its mode.
py::object MethodSummary(const refine::RefineSummary& summary) {
  Json json = ToJson(summary);
  json["mode"] = refine::RefineModeName(summary.mode);
  return JsonToPython(json);
}

py::dict RunPy(const std::filesystem::path& capture_dir,
               const std::filesystem::path& result_dir,
               bool overwrite,
               int num_threads) {
  pipeline::RunOptions o;
  o.capture_dir = capture_dir.string();
  o.result_dir = result_dir.string();
  o.overwrite = overwrite;
  o.num_threads = num_threads;
  // Validated once, here (a ValueError), and run as validated.
  StatusOr<Validated<pipeline::RunOptions>> valid = Validated<pipeline::RunOptions>::Check(o);
  CheckValid(valid.status());
  StatusOr<pipeline::RunSummary> summary = [&] {
    py::gil_scoped_release release;
    return pipeline::RunCapture(*valid);
  }();
  if (!summary.ok()) RaiseStatus(summary.status(), o.capture_dir);
  py::dict timings;
  for (const pipeline::StageTiming& t : summary->timings) timings[py::str(t.name)] = t.seconds;
  py::list methods;
  for (const refine::RefineSummary& m : summary->methods) methods.append(MethodSummary(m));
  py::dict out;
  out["result_dir"] = o.result_dir;
  out["hands"] = JsonToPython(ToJson(summary->hands));
  out["methods"] = methods;
  out["timings_s"] = timings;
  out["warnings"] = summary->warnings;
  return out;
}

py::object RefinePy(const std::filesystem::path& result_dir,
                    const std::string& mode,
                    int num_threads,
                    double min_confidence) {
  pipeline::RefineStageOptions o;
  o.result_dir = result_dir.string();
  StatusOr<refine::RefineMode> parsed = refine::ParseRefineMode(mode);
  CheckValid(parsed.status());
  o.refine.mode = *parsed;
  o.refine.num_threads = num_threads;
  o.refine.pitch.min_confidence = min_confidence;
  StatusOr<Validated<pipeline::RefineStageOptions>> valid =
      Validated<pipeline::RefineStageOptions>::Check(o);
  CheckValid(valid.status());
  StatusOr<refine::RefineSummary> summary = [&] {
    py::gil_scoped_release release;
    return pipeline::RunRefineStage(*valid);
  }();
  if (!summary.ok()) RaiseStatus(summary.status(), o.result_dir);
  return MethodSummary(*summary);
}

}  // namespace

void BindRun(py::module_& m) {
  const pipeline::RunOptions run;
  m.def("run",
        &RunPy,
        "capture"_a,
        "result"_a,
        py::kw_only(),
        "overwrite"_a = run.overwrite,
        "num_threads"_a = run.num_threads,
        R"(`arco run CAPTURE -o RESULT`: every stage (triangulate, instrument, hands, pitch,
refine) on a capture folder, writing the result folder (moved in only when complete).

overwrite: replace an existing result folder (only one holding result.json). num_threads:
0 = all cores (results do not depend on it). Returns a dict: result_dir, hands (the hand
stage's summary), methods (the refinement summary of vision, paper and arco), timings_s
{stage: wall seconds}, warnings. Read the folder with arco.read_result.)");

  const refine::RefineOptions refine;
  m.def("refine",
        &RefinePy,
        "result"_a,
        py::kw_only(),
        "mode"_a = "arco",
        "num_threads"_a = refine.num_threads,
        "min_confidence"_a = refine.pitch.min_confidence,
        R"(`arco refine RESULT --mode MODE`: re-runs one method (paper, arco or vision) of the
audio-guided refinement on a result folder of `arco run`, replacing that method's folder.

Returns the method's summary (pressed, open_string, rest, uncertain frames, notes, ...).)");
}

}  // namespace arco::python
