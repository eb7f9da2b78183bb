// The Python module's shared pieces (docs/python.md): how errors become Python exceptions,
// how arrays cross, and one Bind function per layer, each in its own file:
//   calibration.cc  arco.Camera, arco.Calibration, arco.load_calibration
//   triangulate.cc  arco.triangulate
//   pitch.cc        arco.track_pitch
//   instrument.cc   arco.Instrument, arco.contact_point
//   hand.cc         arco.HandModel
//   eval.cc         arco.evaluate_pitch, arco.evaluate
//   result.cc       arco.read_result
//   run.cc          arco.run, arco.refine (`arco run`, `arco refine`)
//   stages.cc       arco.open_capture, the stages of `arco run` one by one
//                   (arco.triangulate_stage ... arco.refine_stage), arco.write_result
// module.cc defines the module and calls them. Errors:
//   ValueError    bad arguments (Validate(), std::invalid_argument, wrong array shapes)
//   OSError       a file or folder that does not exist
//   RuntimeError  any other expected failure (malformed file, no solution)
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "arco/audio/pitch_tracker.h"
#include "arco/calibration/calibration_file.h"
#include "arco/util/json_io.h"
#include "arco/util/npy.h"
#include "arco/util/status.h"

namespace py = pybind11;

namespace arco::python {

using namespace pybind11::literals;  // NOLINT: "name"_a

// ---- errors -------------------------------------------------------------------------

[[noreturn]] inline void RaiseValueError(const std::string& message) {
  throw py::value_error(message);
}

[[noreturn]] inline void RaiseOsError(const std::string& message) {
  PyErr_SetString(PyExc_OSError, message.c_str());
  throw py::error_already_set();
}

// An expected failure about `path`: OSError when the path does not exist, else
// RuntimeError.
[[noreturn]] inline void RaiseStatus(const Status& status, const std::string& path = "") {
  std::error_code ec;
  if (!path.empty() && !std::filesystem::exists(path, ec)) RaiseOsError(status.message());
  throw std::runtime_error(status.message());
}

inline void CheckValid(const Status& status) {
  if (!status.ok()) RaiseValueError(status.message());
}

// ---- arrays -------------------------------------------------------------------------

// A numpy array that owns `data` (moved, not copied).
template <typename T>
py::array_t<T> ToArray(std::vector<T>&& data, const std::vector<int64_t>& shape) {
  auto* owned = new std::vector<T>(std::move(data));
  py::capsule owner(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  std::vector<py::ssize_t> dims(shape.begin(), shape.end());
  return py::array_t<T>(dims, owned->data(), owner);
}

template <typename T>
py::array_t<T> ToArray(NpyArray<T>&& array) {
  return ToArray(std::move(array.data), array.shape);
}

template <typename T>
py::array_t<T> VectorToArray(std::vector<T>&& data) {
  const int64_t n = static_cast<int64_t>(data.size());
  return ToArray(std::move(data), {n});
}

inline py::array_t<double> MatrixToArray(const Eigen::MatrixXd& m) {
  std::vector<double> data(static_cast<size_t>(m.size()));
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    for (Eigen::Index c = 0; c < m.cols(); ++c) data[r * m.cols() + c] = m(r, c);
  }
  return ToArray(std::move(data), {m.rows(), m.cols()});
}

inline std::string ShapeString(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) {
    if (i) s += ", ";
    s += std::to_string(a.shape(i));
  }
  return s + (a.ndim() == 1 ? ",)" : ")");
}

// A JSON value (result.json, eval.json, a summary) as Python dicts and lists.
inline py::object JsonToPython(const Json& json) {
  return py::module_::import("json").attr("loads")(json.dump());
}

template <typename T>
T ValueOrRaise(StatusOr<T> value, const std::string& path) {
  if (!value.ok()) RaiseStatus(value.status(), path);
  return std::move(*value);
}

// ---- shared between layers -----------------------------------------------------------

struct PyCalibration {
  Calibration calibration;
};
// An arco.Calibration or a path to one (calibration.cc).
PyCalibration CalibrationFrom(const py::object& calibration);
// The columns of pitch.csv as numpy arrays (pitch.cc).
py::dict PitchColumns(const std::vector<audio::PitchFrame>& frames);

void BindCalibration(py::module_& m);
void BindTriangulate(py::module_& m);
void BindPitch(py::module_& m);
void BindInstrument(py::module_& m);
void BindHand(py::module_& m);
void BindEval(py::module_& m);
void BindResult(py::module_& m);
void BindRun(py::module_& m);
void BindStages(py::module_& m);

}  // namespace arco::python
