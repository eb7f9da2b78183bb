// arco.evaluate_pitch and arco.evaluate (`arco eval`).
#include <filesystem>
#include <string>
#include <vector>

#include "arco/eval/evaluate.h"
#include "arco/eval/metrics.h"
#include "arco/python/bindings.h"

namespace arco::python {

// ---- eval ---------------------------------------------------------------------------

py::dict EvaluatePitchPy(
    const py::array_t<double, py::array::c_style | py::array::forcecast>& truth_f0_hz,
    const py::array_t<double, py::array::c_style | py::array::forcecast>& f0_hz,
    const py::object& scored) {
  if (truth_f0_hz.ndim() != 1 || f0_hz.ndim() != 1 || truth_f0_hz.size() != f0_hz.size()) {
    RaiseValueError("truth_f0_hz and f0_hz must be 1-D of one length, got " +
                    ShapeString(truth_f0_hz) + " and " + ShapeString(f0_hz));
  }
  const std::vector<double> truth(truth_f0_hz.data(), truth_f0_hz.data() + truth_f0_hz.size());
  const std::vector<double> estimate(f0_hz.data(), f0_hz.data() + f0_hz.size());
  std::vector<bool> mask;
  if (!scored.is_none()) {
    const auto m = scored.cast<py::array_t<bool, py::array::c_style | py::array::forcecast>>();
    if (m.ndim() != 1 || m.size() != f0_hz.size()) {
      RaiseValueError("scored must be 1-D like f0_hz, got " + ShapeString(m));
    }
    mask.assign(m.data(), m.data() + m.size());
  }
  const eval::PitchMetrics p =
      eval::EvaluatePitch(truth, estimate, scored.is_none() ? nullptr : &mask);
  py::dict out;
  out["frames"] = p.frames;
  out["truth_voiced_frames"] = p.truth_voiced_frames;
  out["rpa50"] = p.rpa50;
  out["rpa25"] = p.rpa25;
  out["voicing_recall"] = p.voicing_recall;
  out["voicing_false_alarm"] = p.voicing_false_alarm;
  out["median_abs_cents"] = p.median_abs_cents;
  return out;
}

// `arco eval`: a result folder against a synthetic truth folder or labelled frames; the dict
// of `arco eval -o eval.json`.
py::object EvaluatePy(const std::filesystem::path& result_dir,
                      const py::object& truth,
                      const std::vector<int64_t>& truth_frames,
                      const std::string& pitch,
                      const std::vector<double>& pck_thresholds_mm,
                      double joint_limit_tolerance_deg) {
  eval::EvalRequest r;
  r.result_dir = result_dir.string();
  // One truth without truth_frames: a synthetic truth folder; else labelled frames.
  if (py::isinstance<py::str>(truth) ||
      py::isinstance(truth, py::module_::import("os").attr("PathLike"))) {
    r.truth = truth.cast<std::filesystem::path>().string();
    if (!truth_frames.empty()) {  // one labelled frame
      r.labels = {r.truth};
      r.truth.clear();
    }
  } else {
    for (const std::filesystem::path& label : truth.cast<std::vector<std::filesystem::path>>()) {
      r.labels.push_back(label.string());
    }
  }
  r.truth_frames = truth_frames;
  r.pitch_csv = pitch;
  r.metrics.pck_thresholds_mm = pck_thresholds_mm;
  r.joint_limit_tolerance_deg = joint_limit_tolerance_deg;
  CheckValid(r.Validate());
  StatusOr<eval::EvalReport> report = [&] {
    py::gil_scoped_release release;
    return eval::Evaluate(r);
  }();
  if (!report.ok()) RaiseStatus(report.status(), r.result_dir);
  Json json = report->ToJson(r.metrics);
  json["options"] = eval::ToJson(r);
  return JsonToPython(json);
}

void BindEval(py::module_& m) {
  m.def("evaluate_pitch",
        &EvaluatePitchPy,
        "truth_f0_hz"_a,
        "f0_hz"_a,
        "scored"_a = py::none(),
        R"(Pitch metrics of `arco eval` (docs/evaluation.md) on per-frame f0 arrays (<= 0 or NaN:
unvoiced); `scored` (bool) leaves frames out. Returns rpa50, rpa25, voicing_recall,
voicing_false_alarm, median_abs_cents, frames, truth_voiced_frames.)");

  const eval::EvalRequest e;
  m.def("evaluate",
        &EvaluatePy,
        "result_dir"_a,
        "truth"_a,
        py::kw_only(),
        "truth_frames"_a = std::vector<int64_t>{},
        "pitch"_a = "",
        "pck_thresholds_mm"_a = e.metrics.pck_thresholds_mm,
        "joint_limit_tolerance_deg"_a = e.joint_limit_tolerance_deg,
        R"(`arco eval`: every method of a result folder scored against truth (docs/evaluation.md).

truth: an `arco synth` truth folder, or points JSONs of labelled views (a list) with
truth_frames. Returns the dict `arco eval -o eval.json` writes.)");
}

}  // namespace arco::python
