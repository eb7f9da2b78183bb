// Cameras and calibrations: arco.Camera, arco.Calibration, arco.load_calibration.
#include <algorithm>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "arco/calibration/calibration_file.h"
#include "arco/camera/calibration_io.h"
#include "arco/python/bindings.h"

namespace arco::python {

// ---- calibration --------------------------------------------------------------------

PyCalibration LoadCalibrationOrRaise(const std::string& path) {
  StatusOr<Calibration> calibration = calibration::LoadCalibration(path);
  if (!calibration.ok()) RaiseStatus(calibration.status(), path);
  return PyCalibration{std::move(*calibration)};
}

// A Calibration object or a path to one.
PyCalibration CalibrationFrom(const py::object& calibration) {
  if (py::isinstance<PyCalibration>(calibration)) return calibration.cast<PyCalibration>();
  if (py::isinstance<py::str>(calibration) ||
      py::isinstance(calibration, py::module_::import("os").attr("PathLike"))) {
    return LoadCalibrationOrRaise(calibration.cast<std::filesystem::path>().string());
  }
  RaiseValueError("calibration must be an arco.Calibration or a path");
}

using MatrixArg = py::array_t<double, py::array::c_style | py::array::forcecast>;

const double* CheckedShape(const MatrixArg& a, const char* field, std::vector<py::ssize_t> shape) {
  if (a.ndim() != static_cast<py::ssize_t>(shape.size()) ||
      !std::equal(shape.begin(), shape.end(), a.shape())) {
    std::string want = "(";
    for (size_t i = 0; i < shape.size(); ++i) want += (i ? ", " : "") + std::to_string(shape[i]);
    RaiseValueError(std::string(field) + " must be " + want + (shape.size() == 1 ? ",)" : ")") +
                    ", got " + ShapeString(a));
  }
  return a.data();
}

// A camera from numpy arrays (OpenCV conventions), checked as every calibration reader's.
Camera MakeCamera(const std::string& name,
                  const MatrixArg& K,
                  const MatrixArg& distortion,
                  const MatrixArg& R,
                  const MatrixArg& t,
                  const std::pair<int, int>& size,
                  const std::string& serial) {
  Camera c;
  c.name = name;
  c.serial = serial;
  c.width = size.first;
  c.height = size.second;
  const double* k = CheckedShape(K, "K", {3, 3});
  c.fx = k[0];
  c.skew = k[1];
  c.cx = k[2];
  c.fy = k[4];
  c.cy = k[5];
  if (k[3] != 0 || k[6] != 0 || k[7] != 0 || k[8] != 1) {
    RaiseValueError("camera '" + name + "': K's last row must be [0, 0, 1] and K[1, 0] 0");
  }
  const double* d = CheckedShape(distortion, "distortion", {5});
  c.distortion.k1 = d[0];
  c.distortion.k2 = d[1];
  c.distortion.p1 = d[2];
  c.distortion.p2 = d[3];
  c.distortion.k3 = d[4];
  const double* r = CheckedShape(R, "R", {3, 3});
  for (int i = 0; i < 9; ++i) c.cam_from_world.rotation(i / 3, i % 3) = r[i];
  const double* tt = CheckedShape(t, "t", {3});
  c.cam_from_world.translation = Eigen::Vector3d(tt[0], tt[1], tt[2]);
  CheckValid(ValidateCamera(c));
  return c;
}

// Projects (N, 3) world points: (N, 2) distorted pixels, NaN behind the camera.
py::array_t<double> ProjectPoints(
    const Camera& camera,
    const py::array_t<double, py::array::c_style | py::array::forcecast>& points) {
  if (points.ndim() != 2 || points.shape(1) != 3) {
    RaiseValueError("points must be (N, 3), got " + ShapeString(points));
  }
  const int64_t n = points.shape(0);
  std::vector<double> out(static_cast<size_t>(2 * n));
  const double* p = points.data();
  for (int64_t i = 0; i < n; ++i) {
    const auto pixel = camera.Project(Eigen::Vector3d(p[3 * i], p[3 * i + 1], p[3 * i + 2]));
    out[2 * i] = pixel ? pixel->x() : NAN;
    out[2 * i + 1] = pixel ? pixel->y() : NAN;
  }
  return ToArray(std::move(out), {n, 2});
}

void BindCalibration(py::module_& m) {
  py::class_<Camera>(m, "Camera", "One calibrated camera (OpenCV pinhole + distortion)")
      .def(py::init(&MakeCamera),
           "name"_a,
           "K"_a,
           "distortion"_a,
           "R"_a,
           "t"_a,
           "size"_a,
           "serial"_a = "",
           "From arrays: K (3, 3), distortion (5,) k1 k2 p1 p2 k3, R (3, 3) and t (3,) "
           "cam_from_world, size (width, height)")
      .def_readonly("name", &Camera::name)
      .def_readonly("serial", &Camera::serial)
      .def_readonly("width", &Camera::width)
      .def_readonly("height", &Camera::height)
      .def_property_readonly("size",
                             [](const Camera& c) { return py::make_tuple(c.width, c.height); })
      .def_property_readonly("K", [](const Camera& c) { return MatrixToArray(c.K()); })
      .def_property_readonly(
          "distortion",
          [](const Camera& c) {
            const Distortion& d = c.distortion;
            return VectorToArray(std::vector<double>{d.k1, d.k2, d.p1, d.p2, d.k3});
          },
          "(5,) k1 k2 p1 p2 k3 (OpenCV order)")
      .def_property_readonly(
          "R",
          [](const Camera& c) { return MatrixToArray(c.cam_from_world.rotation); },
          "(3, 3) rotation cam_from_world")
      .def_property_readonly(
          "t",
          [](const Camera& c) {
            const Eigen::Vector3d& t = c.cam_from_world.translation;
            return VectorToArray(std::vector<double>{t.x(), t.y(), t.z()});
          },
          "(3,) translation cam_from_world (world units)")
      .def_property_readonly("center",
                             [](const Camera& c) {
                               const Eigen::Vector3d p = c.CenterInWorld();
                               return VectorToArray(std::vector<double>{p.x(), p.y(), p.z()});
                             })
      .def("project",
           &ProjectPoints,
           "points"_a,
           "(N, 3) world points -> (N, 2) distorted pixels (NaN behind the camera)")
      .def("__repr__", [](const Camera& c) {
        return "<arco.Camera " + c.name + " " + std::to_string(c.width) + "x" +
               std::to_string(c.height) + ">";
      });

  py::class_<PyCalibration>(m, "Calibration", "A camera rig as read by arco.load_calibration")
      .def(py::init([](const std::vector<Camera>& cameras, const std::string& units) {
             PyCalibration c;
             c.calibration.rig.cameras = cameras;
             c.calibration.rig.units = units;
             CheckValid(ValidateRig(c.calibration.rig));
             return c;
           }),
           "cameras"_a,
           "units"_a = "unknown",
           "A rig of arco.Camera objects; units of world coordinates: mm, m, ...")
      .def_property_readonly("cameras",
                             [](const PyCalibration& c) { return c.calibration.rig.cameras; })
      .def_property_readonly("units",
                             [](const PyCalibration& c) { return c.calibration.rig.units; })
      .def_property_readonly("warnings",
                             [](const PyCalibration& c) { return c.calibration.warnings; })
      .def_property_readonly(
          "format",
          [](const PyCalibration& c) { return CalibrationFormatName(c.calibration.format); })
      .def(
          "camera",
          [](const PyCalibration& c, const std::string& id) {
            const int index = c.calibration.rig.FindCamera(id);
            if (index < 0) RaiseValueError("no camera '" + id + "' in the calibration");
            return c.calibration.rig.cameras[index];
          },
          "id"_a,
          "The camera with this name or serial")
      .def(
          "save",
          [](const PyCalibration& c, const std::filesystem::path& path, const std::string& format) {
            CalibrationFormat f = CalibrationFormat::kUnknown;
            if (!format.empty()) {
              StatusOr<CalibrationFormat> parsed = calibration::CalibrationFormatFromFlag(format);
              CheckValid(parsed.status());
              f = *parsed;
            }
            const Status saved = calibration::SaveCalibration(path.string(), c.calibration.rig, f);
            if (!saved.ok()) throw std::runtime_error(saved.message());
          },
          "path"_a,
          "format"_a = "",
          "Writes the rig (format from the extension, or yaml | opencv-xml | spd | arco)")
      .def("__len__", [](const PyCalibration& c) { return c.calibration.rig.cameras.size(); })
      .def("__repr__", [](const PyCalibration& c) {
        return "<arco.Calibration " + std::to_string(c.calibration.rig.cameras.size()) +
               " cameras, units " + c.calibration.rig.units + ">";
      });

  m.def(
      "load_calibration",
      [](const std::filesystem::path& path) { return LoadCalibrationOrRaise(path.string()); },
      "path"_a,
      "Reads a calibration (Metashape XML, OpenCV YAML/XML, SPD or arco JSON)");
}

}  // namespace arco::python
