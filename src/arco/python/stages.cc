// The stages of `arco run` one by one (pipeline/run_capture.h): arco.open_capture opens a
// capture once (arco.Capture: the CaptureContext, with its calibration, 2D keypoints, audio
// and instrument, and the run's options validated once); each stage takes the capture and
// the records of the stages before it and returns its own (arco.TriangulationRecord,
// InstrumentRecord, HandRecord, PitchRecord, MethodRecord: numpy arrays and dicts as
// properties, the C++ record inside for the next stage); arco.write_result writes a result
// folder from the records, the same bytes as `arco run` (tests/test_stages.py). Long work
// runs with the GIL released.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "arco/hand/hand_params.h"
#include "arco/pipeline/run_capture.h"
#include "arco/python/bindings.h"
#include "arco/refine/contact_annotation.h"

namespace arco::python {
namespace {

using pipeline::CaptureContext;
using pipeline::RunOptions;

// Names the result folder in the stages' messages until write_result is given one.
constexpr char kNoResultDir[] = "RESULT";

struct PyCapture {
  std::shared_ptr<const CaptureContext> context;
  std::optional<Validated<RunOptions>> options;  // the run's, validated once (open_capture)
  const CaptureContext& get() const { return *context; }
  const RunOptions& run() const { return options->get(); }
};

PyCapture OpenCapturePy(const std::filesystem::path& capture_dir,
                        int num_threads,
                        bool double_stops) {
  RunOptions o;
  o.capture_dir = capture_dir.string();
  o.result_dir = kNoResultDir;
  o.num_threads = num_threads;
  o.double_stops = double_stops;
  StatusOr<Validated<RunOptions>> valid = Validated<RunOptions>::Check(o);
  CheckValid(valid.status());
  StatusOr<CaptureContext> opened = [&] {
    py::gil_scoped_release release;
    return pipeline::OpenRunCapture(*valid);
  }();
  PyCapture out;
  out.context =
      std::make_shared<const CaptureContext>(ValueOrRaise(std::move(opened), o.capture_dir));
  out.options = std::move(valid).value();
  return out;
}

template <typename T>
py::array_t<T> ArrayCopy(const NpyArray<T>& array) {
  NpyArray<T> copy = array;
  return ToArray(std::move(copy));
}

// Runs `stage` without the GIL; its error as a Python exception naming the capture.
template <typename F>
auto Released(const PyCapture& capture, F stage) {
  auto made = [&] {
    py::gil_scoped_release release;
    return stage();
  }();
  return ValueOrRaise(std::move(made), capture.get().capture_dir);
}

py::object MethodSummary(const refine::RefineSummary& summary) {
  Json json = ToJson(summary);
  json["mode"] = refine::RefineModeName(summary.mode);
  return JsonToPython(json);
}

void BindCapture(py::module_& m) {
  py::class_<PyCapture>(m,
                        "Capture",
                        "A capture folder opened once (arco.open_capture): its manifest, "
                        "calibration, 2D keypoints, audio and instrument")
      .def_property_readonly("capture_dir", [](const PyCapture& c) { return c.get().capture_dir; })
      .def_property_readonly("fps", [](const PyCapture& c) { return c.get().manifest.fps; })
      .def_property_readonly("frames",
                             [](const PyCapture& c) { return c.get().manifest.frame_count; })
      .def_property_readonly("cameras",
                             [](const PyCapture& c) {
                               std::vector<std::string> names;
                               for (const auto& camera : c.get().manifest.cameras)
                                 names.push_back(camera.name);
                               return names;
                             })
      .def_property_readonly("instrument",
                             [](const PyCapture& c) { return c.get().instrument->name(); })
      .def_property_readonly("layout", [](const PyCapture& c) { return c.get().layout.name; })
      .def_property_readonly("has_audio",
                             [](const PyCapture& c) { return !c.get().manifest.audio.empty(); })
      .def_property_readonly(
          "keypoints2d",
          [](const PyCapture& c) { return ArrayCopy(*c.get().keypoints2d); },
          "(frames, views, keypoints, 3) x, y, score as the stages read them")
      .def("__repr__", [](const PyCapture& c) {
        return "<arco.Capture " + c.get().capture_dir + ": " + c.get().manifest.instrument + ", " +
               std::to_string(c.get().manifest.frame_count) + " frames, " +
               std::to_string(c.get().view_to_camera.size()) + " views>";
      });
}

void BindRecords(py::module_& m) {
  py::class_<pipeline::TriangulateStageResult>(m, "TriangulationRecord", "Stage 1's record")
      .def_property_readonly(
          "points3d",
          [](const pipeline::TriangulateStageResult& r) { return ArrayCopy(r.points3d); },
          "(frames, keypoints, 3) filtered, world units (triangulation/points3d.npy)")
      .def_property_readonly(
          "points3d_raw",
          [](const pipeline::TriangulateStageResult& r) { return ArrayCopy(r.raw.points3d); })
      .def_property_readonly(
          "units", [](const pipeline::TriangulateStageResult& r) { return r.record.units; })
      .def_property_readonly("summary", [](const pipeline::TriangulateStageResult& r) {
        return JsonToPython(ToJson(r.record.summary));
      });
  py::class_<pipeline::InstrumentRecord>(m, "InstrumentRecord", "Stage 2's record")
      .def_property_readonly(
          "strings_mm",
          [](const pipeline::InstrumentRecord& r) { return ArrayCopy(r.strings_mm); },
          "(frames, strings, 2, 3) nut and bridge of each string, mm")
      .def_property_readonly(
          "keypoints_mm",
          [](const pipeline::InstrumentRecord& r) { return ArrayCopy(r.keypoints_mm); })
      .def_readonly("keypoint_names", &pipeline::InstrumentRecord::keypoint_names)
      .def_readonly("world_units_per_mm", &pipeline::InstrumentRecord::world_units_per_mm)
      .def_property_readonly("summary", [](const pipeline::InstrumentRecord& r) {
        return JsonToPython(ToJson(r.summary));
      });
  py::class_<pipeline::HandRecord>(m, "HandRecord", "Stage 3's record")
      .def_property_readonly(
          "hand_params",
          [](const pipeline::HandRecord& r) { return ToArray(hand::HandParams(r.hands)); },
          "(frames, 26) as hand/hand_params.npy (a NaN row: no hand)")
      .def_property_readonly(
          "summary", [](const pipeline::HandRecord& r) { return JsonToPython(ToJson(r.summary)); });
  py::class_<pipeline::PitchRecord>(m, "PitchRecord", "Stage 4's record")
      .def_property_readonly("ran", [](const pipeline::PitchRecord& r) { return r.summary.ran; })
      .def_property_readonly(
          "frames",
          [](const pipeline::PitchRecord& r) { return PitchColumns(r.frames); },
          "pitch.csv's columns, one row per video frame")
      .def_property_readonly(
          "notes",
          [](const pipeline::PitchRecord& r) { return static_cast<int64_t>(r.notes.notes.size()); },
          "the number of notes (notes.csv)")
      .def_property_readonly("summary", [](const pipeline::PitchRecord& r) {
        return JsonToPython(ToJson(r.summary));
      });
  py::class_<pipeline::MethodRecord>(m, "MethodRecord", "Stage 5's record of one method")
      .def_readonly("method", &pipeline::MethodRecord::method)
      .def_property_readonly(
          "points3d",
          [](const pipeline::MethodRecord& r) { return ArrayCopy(r.points3d); },
          "(frames, points, 3) mm in the method's layout (METHOD/points3d.npy)")
      .def_property_readonly(
          "hand_params",
          [](const pipeline::MethodRecord& r) { return ToArray(hand::HandParams(r.hands)); })
      .def_property_readonly(
          "summary", [](const pipeline::MethodRecord& r) { return MethodSummary(r.summary); });
}

pipeline::TriangulateStageResult TriangulatePy(const PyCapture& c) {
  return Released(c,
                  [&] { return pipeline::RunTriangulateStage(c.run().ForTriangulate(), c.get()); });
}

pipeline::InstrumentRecord InstrumentPy(const PyCapture& c,
                                        const pipeline::TriangulateStageResult& triangulation) {
  return Released(c, [&] {
    return pipeline::RunInstrumentStage(c.run().ForInstrument(), c.get(), triangulation);
  });
}

pipeline::HandRecord HandPy(const PyCapture& c,
                            const pipeline::TriangulateStageResult& triangulation,
                            const pipeline::InstrumentRecord& instrument) {
  return Released(c, [&] {
    return pipeline::RunHandStage(c.run().ForHands(), c.get(), triangulation, instrument);
  });
}

pipeline::PitchRecord PitchPy(const PyCapture& c) {
  return Released(c, [&] { return pipeline::RunPitchStage(c.run().ForPitch(), c.get()); });
}

// The records of stages 1-4 (copies: the Python objects stay as they are).
pipeline::RunRecords Records(const pipeline::TriangulateStageResult& triangulation,
                             const pipeline::InstrumentRecord& instrument,
                             const pipeline::HandRecord& hand,
                             const pipeline::PitchRecord& pitch) {
  pipeline::RunRecords records;
  records.triangulation = triangulation;
  records.instrument = instrument;
  records.hand = hand;
  records.pitch = pitch;
  return records;
}

std::vector<pipeline::MethodRecord> RefinePy(const PyCapture& c,
                                             const pipeline::TriangulateStageResult& triangulation,
                                             const pipeline::InstrumentRecord& instrument,
                                             const pipeline::HandRecord& hand,
                                             const pipeline::PitchRecord& pitch) {
  const pipeline::RunRecords records = Records(triangulation, instrument, hand, pitch);
  return Released(c, [&] { return pipeline::RunRefineMethods(c.run(), c.get(), records); });
}

void WriteResultPy(const PyCapture& c,
                   const std::filesystem::path& result_dir,
                   const pipeline::TriangulateStageResult& triangulation,
                   const pipeline::InstrumentRecord& instrument,
                   const pipeline::HandRecord& hand,
                   const pipeline::PitchRecord& pitch,
                   const std::vector<pipeline::MethodRecord>& methods,
                   bool overwrite) {
  RunOptions o = c.run();
  o.result_dir = result_dir.string();
  o.overwrite = overwrite;
  StatusOr<Validated<RunOptions>> valid = Validated<RunOptions>::Check(o);
  CheckValid(valid.status());
  pipeline::RunRecords records = Records(triangulation, instrument, hand, pitch);
  records.methods = methods;
  const Status written = [&] {
    py::gil_scoped_release release;
    return pipeline::WriteRunResult(*valid, c.get(), std::move(records));
  }();
  if (!written.ok()) RaiseStatus(written, o.result_dir);
}

}  // namespace

void BindStages(py::module_& m) {
  BindCapture(m);
  BindRecords(m);
  const RunOptions run;
  m.def("open_capture",
        &OpenCapturePy,
        "capture"_a,
        py::kw_only(),
        "num_threads"_a = run.num_threads,
        "double_stops"_a = run.double_stops,
        R"(Opens a capture folder once for running the stages of `arco run` one by one: reads
and checks capture.json, the calibration, keypoints2d.npy and the audio as `arco run` does
before its first stage. The stages then run with `arco run`'s options (num_threads: 0 = all
cores, results do not depend on it; double_stops: `arco run --double-stops`).)");
  m.def("triangulate_stage",
        &TriangulatePy,
        "capture"_a,
        "Stage 1: the capture's 2D keypoints triangulated and filtered (a TriangulationRecord).");
  m.def("instrument_stage",
        &InstrumentPy,
        "capture"_a,
        "triangulation"_a,
        "Stage 2: the instrument fitted to the triangulation (an InstrumentRecord).");
  m.def("hand_stage",
        &HandPy,
        "capture"_a,
        "triangulation"_a,
        "instrument"_a,
        "Stage 3: the left hand fitted to every frame (a HandRecord).");
  m.def("pitch_stage",
        &PitchPy,
        "capture"_a,
        "Stage 4: the pitch and notes of the capture's audio (a PitchRecord; ran is False "
        "without audio).");
  m.def("refine_stage",
        &RefinePy,
        "capture"_a,
        "triangulation"_a,
        "instrument"_a,
        "hand"_a,
        "pitch"_a,
        "Stage 5: the refinement's methods, vision, then paper and arco when the pitch ran (a "
        "list of MethodRecord).");
  m.def("write_result",
        &WriteResultPy,
        "capture"_a,
        "result"_a,
        "triangulation"_a,
        "instrument"_a,
        "hand"_a,
        "pitch"_a,
        "methods"_a,
        py::kw_only(),
        "overwrite"_a = false,
        R"(Writes the result folder RESULT from the stages' records as `arco run` writes it
(moved into place when complete; an existing one replaced only with overwrite): the same
files, byte for byte, as `arco run` with the capture's options.)");
}

}  // namespace arco::python
