// arco.triangulate: robust multi-view triangulation of keypoint arrays.
#include <string>
#include <utility>
#include <vector>

#include "arco/mocap/capture.h"
#include "arco/mocap/triangulate_sequence.h"
#include "arco/python/bindings.h"

namespace arco::python {

// ---- triangulation ------------------------------------------------------------------

// Copies `array` (any real dtype, any layout) into the library's float64 array: one pass,
// float32 keypoints (keypoints2d.npy) converted as they are copied.
NpyArray<double> ToNpyArray(const py::array& array) {
  // The dtype rule of keypoints2d.npy (mocap::CheckKeypoints2dDtype), shared with the CLI:
  // integer pixels are a writer's mistake, not something to convert silently.
  CheckValid(CheckKeypoints2dDtype(
      "keypoints2d", py::str(array.dtype()).cast<std::string>(), array.dtype().kind() == 'f'));
  NpyArray<double> out;
  out.shape.assign(array.shape(), array.shape() + array.ndim());
  if (py::isinstance<py::array_t<float>>(array)) {
    const auto f = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(array);
    out.data.assign(f.data(), f.data() + f.size());
  } else {
    const auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(array);
    if (!d) throw py::error_already_set();
    out.data.assign(d.data(), d.data() + d.size());
  }
  return out;
}

py::dict Triangulate(const py::object& keypoints2d_arg,
                     const py::object& calibration_arg,
                     const py::object& cameras,
                     double min_score,
                     double max_reprojection_px,
                     int max_ransac_trials,
                     double ransac_confidence,
                     uint64_t seed,
                     bool weight_by_score,
                     bool refine,
                     double robust_loss_scale_px,
                     int max_refine_iterations,
                     int num_threads) {
  const py::array keypoints2d = py::array::ensure(keypoints2d_arg);
  if (!keypoints2d) RaiseValueError("keypoints2d must be a numpy array (or convertible to one)");
  if (keypoints2d.ndim() != 4 || keypoints2d.shape(3) != 3) {
    RaiseValueError("keypoints2d must be (frames, views, points, 3) [x, y, score], got " +
                    ShapeString(keypoints2d));
  }
  const PyCalibration calibration = CalibrationFrom(calibration_arg);
  const Rig& rig = calibration.calibration.rig;
  const int64_t views = keypoints2d.shape(1);
  std::vector<int> view_to_camera;
  if (cameras.is_none()) {
    if (views > static_cast<int64_t>(rig.cameras.size())) {
      RaiseValueError("keypoints2d has " + std::to_string(views) + " views, the calibration " +
                      std::to_string(rig.cameras.size()) + " cameras; give cameras=");
    }
    for (int v = 0; v < views; ++v) view_to_camera.push_back(v);
  } else {
    for (const py::handle item : cameras) {
      if (py::isinstance<py::str>(item)) {
        const std::string id = item.cast<std::string>();
        const int index = rig.FindCamera(id);
        if (index < 0) RaiseValueError("cameras: no camera '" + id + "' in the calibration");
        view_to_camera.push_back(index);
      } else {
        const int index = item.cast<int>();
        if (index < 0 || index >= static_cast<int>(rig.cameras.size())) {
          RaiseValueError("cameras: index " + std::to_string(index) + " outside 0.." +
                          std::to_string(rig.cameras.size() - 1));
        }
        view_to_camera.push_back(index);
      }
    }
    if (static_cast<int64_t>(view_to_camera.size()) != views) {
      RaiseValueError("cameras names " + std::to_string(view_to_camera.size()) +
                      " cameras, keypoints2d has " + std::to_string(views) + " views");
    }
  }
  SequenceTriangulationOptions options;
  TriangulationOptions& p = options.point;
  p.min_score = min_score;
  p.max_reprojection_px = max_reprojection_px;
  p.max_ransac_trials = max_ransac_trials;
  p.ransac_confidence = ransac_confidence;
  p.seed = seed;
  p.weight_by_score = weight_by_score;
  p.refine = refine;
  p.robust_loss_scale_px = robust_loss_scale_px;
  p.max_refine_iterations = max_refine_iterations;
  options.num_threads = num_threads;
  CheckValid(options.Validate());

  const NpyArray<double> input = ToNpyArray(keypoints2d);
  StatusOr<SequenceTriangulation> result = [&] {
    py::gil_scoped_release release;
    return TriangulateSequence(rig, view_to_camera, input, options);
  }();
  if (!result.ok()) RaiseValueError(result.status().message());
  py::dict out;
  out["points3d"] = ToArray(std::move(result->points3d));
  out["rms_reprojection_px"] = ToArray(std::move(result->rms_reprojection_px));
  out["num_inliers"] = ToArray(std::move(result->num_inliers));
  out["num_views"] = ToArray(std::move(result->num_views));
  out["inlier_mask"] =
      ToArray(std::move(result->inlier_mask)).attr("view")("bool");  // 0 or 1: no copy
  return out;
}

void BindTriangulate(py::module_& m) {
  const SequenceTriangulationOptions d;
  m.def("triangulate",
        &Triangulate,
        "keypoints2d"_a,
        "calibration"_a,
        py::kw_only(),
        "cameras"_a = py::none(),
        "min_score"_a = d.point.min_score,
        "max_reprojection_px"_a = d.point.max_reprojection_px,
        "max_ransac_trials"_a = d.point.max_ransac_trials,
        "ransac_confidence"_a = d.point.ransac_confidence,
        "seed"_a = d.point.seed,
        "weight_by_score"_a = d.point.weight_by_score,
        "refine"_a = d.point.refine,
        "robust_loss_scale_px"_a = d.point.robust_loss_scale_px,
        "max_refine_iterations"_a = d.point.max_refine_iterations,
        "num_threads"_a = d.num_threads,
        R"(Robust multi-view triangulation of (F, V, P, 3) [x, y, score] keypoints (NaN missing).

cameras: the calibration camera (name, serial or index) of each view; default the first V.
Returns a dict: points3d (F, P, 3) in calibration units, NaN where not triangulated;
rms_reprojection_px (F, P); num_inliers (F, P); num_views (F, P); inlier_mask (F, P, V).)");
}

}  // namespace arco::python
