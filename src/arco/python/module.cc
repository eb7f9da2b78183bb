// `import arco`: the Python bindings (docs/python.md). A thin layer over the libraries:
// arrays in and out as numpy (results are moved into arrays that own them, no copies),
// options as keyword arguments checked by the options structs' Validate(), errors as
// Python exceptions carrying the library's one-line messages:
//   ValueError    bad arguments (Validate(), std::invalid_argument, wrong array shapes)
//   OSError       a file or folder that does not exist
//   RuntimeError  any other expected failure (malformed file, no solution)
// Long C++ work runs with the GIL released.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "arco/audio/audio_reader.h"
#include "arco/audio/pitch_tracker.h"
#include "arco/calibration/calibration_file.h"
#include "arco/camera/calibration_io.h"
#include "arco/eval/evaluate.h"
#include "arco/eval/metrics.h"
#include "arco/hand/hand_model.h"
#include "arco/hand/hand_params.h"
#include "arco/hand/ik.h"
#include "arco/hand/kinematics.h"
#include "arco/instrument/contact.h"
#include "arco/instrument/instrument_model.h"
#include "arco/mocap/capture.h"
#include "arco/mocap/triangulate_sequence.h"
#include "arco/pipeline/pitch_sync.h"
#include "arco/pipeline/result_folder.h"
#include "arco/refine/contacts_csv.h"

namespace py = pybind11;
using namespace pybind11::literals;  // NOLINT: "name"_a
namespace arco::python {
namespace {

// ---- errors -------------------------------------------------------------------------

[[noreturn]] void RaiseValueError(const std::string& message) { throw py::value_error(message); }

[[noreturn]] void RaiseOsError(const std::string& message) {
  PyErr_SetString(PyExc_OSError, message.c_str());
  throw py::error_already_set();
}

// An expected failure about `path`: OSError when the path does not exist, else
// RuntimeError.
[[noreturn]] void RaiseStatus(const Status& status, const std::string& path = "") {
  std::error_code ec;
  if (!path.empty() && !std::filesystem::exists(path, ec)) RaiseOsError(status.message());
  throw std::runtime_error(status.message());
}

void CheckValid(const Status& status) {
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

py::array_t<double> MatrixToArray(const Eigen::MatrixXd& m) {
  std::vector<double> data(static_cast<size_t>(m.size()));
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    for (Eigen::Index c = 0; c < m.cols(); ++c) data[r * m.cols() + c] = m(r, c);
  }
  return ToArray(std::move(data), {m.rows(), m.cols()});
}

std::string ShapeString(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) {
    if (i) s += ", ";
    s += std::to_string(a.shape(i));
  }
  return s + (a.ndim() == 1 ? ",)" : ")");
}

// ---- calibration --------------------------------------------------------------------

struct PyCalibration {
  Calibration calibration;
};

PyCalibration LoadCalibrationOrRaise(const std::string& path) {
  StatusOr<Calibration> calibration = LoadCalibration(path);
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
  for (int i = 0; i < 9; ++i) c.cam_from_world_rotation(i / 3, i % 3) = r[i];
  const double* tt = CheckedShape(t, "t", {3});
  c.cam_from_world_translation = Eigen::Vector3d(tt[0], tt[1], tt[2]);
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

// ---- pitch --------------------------------------------------------------------------

// Float samples held by the caller (the numpy array outlives the reader), (frames,) or
// interleaved (frames, channels). Mixed down as the file readers do (audio/audio_reader.h:
// the channels' float sum times 1 / channels), so a WAV's samples give `arco pitch`'s rows;
// TrackPitch refuses non-finite samples first, with the readers' check (CheckSamples).
class SamplesReader : public audio::AudioReader {
 public:
  SamplesReader(const float* samples, int64_t frames, int channels, int rate_hz)
      : samples_(samples), frames_(frames), channels_(channels) {
    info_.sample_rate_hz = rate_hz;
    info_.channels = channels;
    info_.frames = frames;
    info_.format = "float32 samples";
    info_.source = "samples";
  }
  StatusOr<int64_t> ReadMono(float* out, int64_t max_frames) override {
    const int64_t n = std::min(max_frames, frames_ - position_);
    const float scale = 1.0f / static_cast<float>(channels_);
    for (int64_t i = 0; i < n; ++i) {
      const float* frame = samples_ + (position_ + i) * channels_;
      float sum = 0.0f;
      for (int c = 0; c < channels_; ++c) sum += frame[c];
      out[i] = sum * scale;
    }
    position_ += n;
    return n;
  }

 private:
  const float* samples_;
  int64_t frames_;
  int channels_;
  int64_t position_ = 0;
};

py::dict PitchColumns(const std::vector<audio::PitchFrame>& frames) {
  const size_t n = frames.size();
  std::vector<int64_t> frame(n);
  std::vector<double> time_s(n), f0_hz(n), confidence(n);
  std::vector<uint8_t> voiced(n);
  for (size_t i = 0; i < n; ++i) {
    frame[i] = frames[i].frame;
    time_s[i] = frames[i].time_s;
    f0_hz[i] = frames[i].f0_hz;
    confidence[i] = frames[i].confidence;
    voiced[i] = frames[i].voiced;
  }
  py::dict out;
  out["frame"] = VectorToArray(std::move(frame));
  out["time_s"] = VectorToArray(std::move(time_s));
  out["f0_hz"] = VectorToArray(std::move(f0_hz));
  out["confidence"] = VectorToArray(std::move(confidence));
  out["voiced"] = VectorToArray(std::move(voiced)).attr("view")("bool");
  return out;
}

py::dict TrackPitch(const py::array_t<float, py::array::c_style | py::array::forcecast>& samples,
                    int sample_rate,
                    double fps,
                    const std::string& instrument,
                    double start_s,
                    int64_t frames,
                    int hops_per_frame,
                    double a4_hz,
                    double min_f0_hz,
                    double max_f0_hz) {
  if (samples.ndim() != 1 && samples.ndim() != 2) {
    RaiseValueError("samples must be (frames,) or (frames, channels), got " + ShapeString(samples));
  }
  const int channels = samples.ndim() == 2 ? static_cast<int>(samples.shape(1)) : 1;
  if (channels < 1 || channels > 1024) {
    RaiseValueError("samples have " + std::to_string(channels) + " channels (1..1024)");
  }
  if (sample_rate < audio::kMinRateHz || sample_rate > audio::kMaxRateHz) {
    RaiseValueError("sample_rate " + std::to_string(sample_rate) + " outside " +
                    std::to_string(audio::kMinRateHz) + ".." + std::to_string(audio::kMaxRateHz) +
                    " Hz");
  }
  // PitchRunOptions reads NaN as "the default"; here a NaN is the caller's value.
  CheckValid(CheckInRange("fps", fps, audio::kTrackerFpsRange));
  CheckValid(CheckInRange("start_s", start_s, audio::kTrackerStartRangeS));
  CheckValid(CheckInRange("a4_hz", a4_hz, kA4RangeHz));
  CheckValid(
      audio::CheckSamples(samples.data(), samples.size(), channels, 0, sample_rate, "samples"));
  pipeline::PitchRunOptions o;
  o.instrument = instrument;
  o.fps = fps;
  o.start_s = start_s;
  o.frames = frames;
  o.hops_per_frame = hops_per_frame;
  o.a4_hz = a4_hz;
  o.min_f0_hz = min_f0_hz;
  o.max_f0_hz = max_f0_hz;
  const StatusOr<audio::PitchTrackerOptions> tracker = pipeline::PitchTrackerOptionsFor(o);
  CheckValid(tracker.status());
  audio::PitchSummary summary;
  auto reader =
      std::make_unique<SamplesReader>(samples.data(), samples.shape(0), channels, sample_rate);
  StatusOr<audio::PitchTrack> track = [&] {
    py::gil_scoped_release release;
    return audio::TrackPitch(std::move(reader), *tracker, &summary);
  }();
  if (!track.ok()) throw std::runtime_error(track.status().message());
  return PitchColumns(track->frames);
}

// ---- instrument ---------------------------------------------------------------------

using PyInstrument = std::shared_ptr<const InstrumentModel>;

PyInstrument MakeInstrument(const std::string& name, double a4_hz) {
  StatusOr<InstrumentKind> kind = ParseInstrumentKind(name);
  CheckValid(kind.status());
  InstrumentOptions options;
  options.kind = *kind;
  options.tuning.a4_hz = a4_hz;
  StatusOr<InstrumentModel> model = InstrumentModel::Create(options);
  CheckValid(model.status());
  return std::make_shared<const InstrumentModel>(std::move(*model));
}

PyInstrument InstrumentFrom(const py::object& instrument) {
  if (py::isinstance<py::str>(instrument))
    return MakeInstrument(instrument.cast<std::string>(), 440);
  return instrument.cast<PyInstrument>();
}

py::object ContactPointPy(
    const py::object& instrument_arg,
    int string,
    const py::array_t<double, py::array::c_style | py::array::forcecast>& f0_hz,
    double open_tolerance_cents,
    double range_tolerance_cents,
    bool physical_correction) {
  const PyInstrument instrument = InstrumentFrom(instrument_arg);
  ContactOptions options;
  options.open_tolerance_cents = open_tolerance_cents;
  options.range_tolerance_cents = range_tolerance_cents;
  options.physical_correction = physical_correction;
  CheckValid(options.Validate());
  const size_t n = static_cast<size_t>(f0_hz.size());
  std::vector<Contact> contacts(n);
  const double* data = f0_hz.data();
  for (size_t i = 0; i < n; ++i) contacts[i] = ContactPoint(*instrument, string, data[i], options);
  auto fill = [&](auto field) {
    std::vector<double> v(n);
    for (size_t i = 0; i < n; ++i) v[i] = contacts[i].*field;
    return v;
  };
  std::vector<int64_t> shape(f0_hz.shape(), f0_hz.shape() + f0_hz.ndim());
  py::dict out;
  if (f0_hz.ndim() == 0) {
    const Contact& c = contacts[0];
    out["kind"] = ContactKindName(c.kind);
    out["stopped"] = c.stopped();
    out["string"] = c.string;
    out["f0_hz"] = c.f0_hz;
    out["cents_from_open"] = c.cents_from_open;
    out["stop_from_bridge_mm"] = c.stop_from_bridge_mm;
    out["contact_from_bridge_mm"] = c.contact_from_bridge_mm;
    out["fraction_from_bridge"] = c.fraction_from_bridge;
    return std::move(out);
  }
  py::list kinds;
  std::vector<uint8_t> stopped(n);
  for (size_t i = 0; i < n; ++i) {
    kinds.append(ContactKindName(contacts[i].kind));
    stopped[i] = contacts[i].stopped();
  }
  out["kind"] =
      py::module_::import("numpy").attr("array")(kinds).attr("reshape")(f0_hz.attr("shape"));
  out["stopped"] = ToArray(std::move(stopped), shape).attr("view")("bool");
  out["string"] = string;
  out["f0_hz"] = ToArray(fill(&Contact::f0_hz), shape);
  out["cents_from_open"] = ToArray(fill(&Contact::cents_from_open), shape);
  out["stop_from_bridge_mm"] = ToArray(fill(&Contact::stop_from_bridge_mm), shape);
  out["contact_from_bridge_mm"] = ToArray(fill(&Contact::contact_from_bridge_mm), shape);
  out["fraction_from_bridge"] = ToArray(fill(&Contact::fraction_from_bridge), shape);
  return std::move(out);
}

// ---- hand ---------------------------------------------------------------------------

using PyHandModel = std::shared_ptr<const hand::HandModel>;
using HandParamsArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

PyHandModel MakeHandModel(const std::string& side, const py::object& bone_lengths_mm) {
  hand::HandSide s;
  if (side == "left") {
    s = hand::HandSide::kLeft;
  } else if (side == "right") {
    s = hand::HandSide::kRight;
  } else {
    RaiseValueError("side must be left or right, got '" + side + "'");
  }
  hand::HandModel model = hand::HandModel::Default(s);
  if (!bone_lengths_mm.is_none()) {
    const auto lengths = bone_lengths_mm.cast<HandParamsArray>();
    if (lengths.ndim() != 1 || lengths.shape(0) != hand::kNumHandKeypoints) {
      RaiseValueError("bone_lengths_mm must be (21,) (entry 0 unused), got " +
                      ShapeString(lengths));
    }
    hand::BoneLengthsMm l{};
    std::copy(lengths.data(), lengths.data() + hand::kNumHandKeypoints, l.begin());
    l[0] = 0;
    StatusOr<hand::HandModel> scaled = model.WithBoneLengths(l);
    CheckValid(scaled.status());
    model = std::move(*scaled);
  }
  return std::make_shared<const hand::HandModel>(std::move(model));
}

hand::HandPose PoseFromRow(const double* row) {
  hand::HandPose pose;
  pose.SetWristAngleAxis(Eigen::Vector3d(row[0], row[1], row[2]));
  pose.wrist_in_world_mm = Eigen::Vector3d(row[3], row[4], row[5]);
  std::copy(row + 6, row + hand::kHandParamsColumns, pose.angles_rad.begin());
  return pose;
}

std::vector<double> RowFromPose(const hand::HandPose& pose) {
  std::vector<double> row(hand::kHandParamsColumns);
  const Eigen::Vector3d aa = pose.WristAngleAxis();
  for (int k = 0; k < 3; ++k) {
    row[k] = aa[k];
    row[3 + k] = pose.wrist_in_world_mm[k];
  }
  std::copy(pose.angles_rad.begin(), pose.angles_rad.end(), row.begin() + 6);
  return row;
}

void CheckParamsShape(const py::array& params) {
  if (params.ndim() < 1 || params.shape(params.ndim() - 1) != hand::kHandParamsColumns) {
    RaiseValueError(
        "params must be (..., 26) [wrist angle-axis (3), wrist mm (3), 20 joint "
        "angles (rad)], got " +
        ShapeString(params));
  }
}

// (..., 26) hand_params rows -> (..., 21, 3) keypoints in world mm; NaN rows -> NaN.
py::array_t<double> ForwardKinematicsPy(const hand::HandModel& model,
                                        const HandParamsArray& params) {
  CheckParamsShape(params);
  const int64_t rows = params.size() / hand::kHandParamsColumns;
  std::vector<double> out(static_cast<size_t>(rows * hand::kNumHandKeypoints * 3), NAN);
  const double* data = params.data();
  {
    py::gil_scoped_release release;
    for (int64_t r = 0; r < rows; ++r) {
      const double* row = data + r * hand::kHandParamsColumns;
      if (!std::all_of(
              row, row + hand::kHandParamsColumns, [](double v) { return std::isfinite(v); })) {
        continue;
      }
      const hand::HandPointsMm points = hand::ForwardKinematics(model, PoseFromRow(row));
      for (int k = 0; k < hand::kNumHandKeypoints; ++k) {
        for (int c = 0; c < 3; ++c) out[(r * hand::kNumHandKeypoints + k) * 3 + c] = points[k][c];
      }
    }
  }
  std::vector<int64_t> shape(params.shape(), params.shape() + params.ndim() - 1);
  shape.push_back(hand::kNumHandKeypoints);
  shape.push_back(3);
  return ToArray(std::move(out), shape);
}

py::dict FingertipIkPy(const hand::HandModel& model,
                       const HandParamsArray& params,
                       int finger,
                       const HandParamsArray& target_mm,
                       const std::string& joints,
                       double reference_weight_mm_per_rad,
                       double max_change_deg,
                       bool exact_reach,
                       int max_iterations) {
  CheckParamsShape(params);
  if (params.ndim() != 1)
    RaiseValueError("params must be one (26,) row, got " + ShapeString(params));
  if (target_mm.ndim() != 1 || target_mm.shape(0) != 3) {
    RaiseValueError("target_mm must be (3,), got " + ShapeString(target_mm));
  }
  if (finger < 0 || finger >= hand::kNumFingers) {
    RaiseValueError("finger " + std::to_string(finger) + " outside 0..4 (0 = thumb, 1 = index)");
  }
  hand::FingerIkOptions options;
  bool known = false;
  for (hand::FingerIkJoints j : {hand::FingerIkJoints::kPipDip,
                                 hand::FingerIkJoints::kMcpFlexPipDip,
                                 hand::FingerIkJoints::kAll}) {
    if (joints == hand::FingerIkJointsName(j)) {
      options.joints = j;
      known = true;
    }
  }
  if (!known)
    RaiseValueError("joints must be pip_dip, mcp_flex_pip_dip or all, got '" + joints + "'");
  options.reference_weight_mm_per_rad = reference_weight_mm_per_rad;
  options.max_change_deg = max_change_deg;
  options.exact_reach = exact_reach;
  options.max_iterations = max_iterations;
  CheckValid(options.Validate());
  const hand::HandPose reference = PoseFromRow(params.data());
  const Eigen::Vector3d target(target_mm.data()[0], target_mm.data()[1], target_mm.data()[2]);
  hand::FingerIkResult r;
  {
    py::gil_scoped_release release;
    r = hand::SolveFingertipIk(
        model, reference, static_cast<hand::Finger>(finger), target, options);
  }
  if (!r.status.ok()) RaiseValueError(r.status.message());
  py::dict out;
  out["params"] = VectorToArray(RowFromPose(r.pose));
  out["converged"] = r.converged;
  out["iterations"] = r.iterations;
  out["initial_distance_mm"] = r.initial_distance_mm;
  out["final_distance_mm"] = r.final_distance_mm;
  out["active_limit_dofs"] = r.active_limit_dofs;
  out["step_limited"] = r.step_limited;
  out["termination"] = r.termination;
  return out;
}

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
  return py::module_::import("json").attr("loads")(json.dump());
}

// ---- result folder ------------------------------------------------------------------

py::dict ContactColumns(const std::vector<refine::ContactRow>& rows) {
  const size_t n = rows.size();
  std::vector<int64_t> frame(n);
  std::vector<int32_t> string(n), finger(n), note(n), open_string(n);
  std::vector<double> point(3 * n), from_nut(n), f0(n), confidence(n), vision(n), refined(n);
  py::list state, reason;
  for (size_t i = 0; i < n; ++i) {
    const refine::ContactRow& r = rows[i];
    frame[i] = r.frame;
    string[i] = r.string;
    finger[i] = r.finger;
    note[i] = r.note;
    open_string[i] = r.open_string;
    for (int k = 0; k < 3; ++k) point[3 * i + k] = r.point_mm[k];
    from_nut[i] = r.from_nut_mm;
    f0[i] = r.f0_hz;
    confidence[i] = r.confidence;
    vision[i] = r.tip_distance_vision_mm;
    refined[i] = r.tip_distance_refined_mm;
    state.append(r.state);
    reason.append(r.reason);
  }
  auto np_array = py::module_::import("numpy").attr("array");
  py::dict out;
  out["frame"] = VectorToArray(std::move(frame));
  out["state"] = np_array(state, "dtype"_a = "str");
  out["reason"] = np_array(reason, "dtype"_a = "str");
  out["string"] = VectorToArray(std::move(string));
  out["finger"] = VectorToArray(std::move(finger));
  out["note"] = VectorToArray(std::move(note));
  out["contact_mm"] = ToArray(std::move(point), {static_cast<int64_t>(n), 3});
  out["from_nut_mm"] = VectorToArray(std::move(from_nut));
  out["f0_hz"] = VectorToArray(std::move(f0));
  out["confidence"] = VectorToArray(std::move(confidence));
  out["tip_distance_vision_mm"] = VectorToArray(std::move(vision));
  out["tip_distance_refined_mm"] = VectorToArray(std::move(refined));
  out["open_string"] = VectorToArray(std::move(open_string));
  return out;
}

template <typename T>
T ValueOrRaise(StatusOr<T> value, const std::string& path) {
  if (!value.ok()) RaiseStatus(value.status(), path);
  return std::move(*value);
}

py::dict ReadResult(const std::filesystem::path& dir_path) {
  const std::string dir = dir_path.string();
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) RaiseOsError(dir + ": no such result folder");
  const pipeline::ResultFolder folder(dir);
  if (!std::filesystem::exists(folder.ManifestPath(), ec)) {
    RaiseOsError(folder.ManifestPath() + ": not found (not an arco result folder)");
  }
  const Json manifest = ValueOrRaise(folder.ReadManifest(), folder.ManifestPath());
  py::dict out;
  out["dir"] = dir;
  out["result"] = py::module_::import("json").attr("loads")(manifest.dump());
  const pipeline::ResultHeader header = ValueOrRaise(folder.ReadHeader(), folder.ManifestPath());
  py::dict points3d, keypoint_names, contacts;
  for (const pipeline::PointStage& stage :
       ValueOrRaise(folder.PointStages(), folder.ManifestPath())) {
    keypoint_names[py::str(stage.name)] =
        stage.keypoint_names.empty() ? header.keypoint_names : stage.keypoint_names;
    points3d[py::str(stage.name)] =
        ToArray(ValueOrRaise(ReadNpy<double>(stage.points3d_path), stage.points3d_path));
    if (!stage.contacts_path.empty() && std::filesystem::exists(stage.contacts_path, ec)) {
      contacts[py::str(stage.name)] = ContactColumns(
          ValueOrRaise(refine::ReadContactsCsv(stage.contacts_path), stage.contacts_path));
    }
  }
  out["points3d"] = points3d;
  out["keypoint_names"] = keypoint_names;
  out["contacts"] = contacts;
  out["pitch"] = py::none();
  if (std::filesystem::exists(folder.PitchPath(), ec)) {
    out["pitch"] = PitchColumns(ValueOrRaise(folder.ReadPitch(), folder.PitchPath()));
  }
  out["instrument"] = py::none();
  if (ValueOrRaise(folder.HasStage(pipeline::kInstrumentStage), folder.ManifestPath())) {
    pipeline::InstrumentRecord record =
        ValueOrRaise(folder.ReadInstrument(), folder.InstrumentStringsPath());
    py::dict instrument;
    instrument["name"] = record.instrument;
    instrument["a4_hz"] = record.a4_hz;
    instrument["world_units_per_mm"] = record.world_units_per_mm;
    instrument["keypoint_names"] = record.keypoint_names;
    instrument["strings_mm"] = ToArray(std::move(record.strings_mm));
    instrument["keypoints_mm"] = ToArray(std::move(record.keypoints_mm));
    out["instrument"] = instrument;
  }
  out["hand_params"] = py::none();
  out["bone_lengths_mm"] = py::none();
  if (std::filesystem::exists(folder.HandParamsPath(), ec)) {
    out["hand_params"] =
        ToArray(ValueOrRaise(ReadNpy<double>(folder.HandParamsPath()), folder.HandParamsPath()));
    out["bone_lengths_mm"] =
        ToArray(ValueOrRaise(ReadNpy<double>(folder.BoneLengthsPath()), folder.BoneLengthsPath()));
  }
  return out;
}

}  // namespace
}  // namespace arco::python

PYBIND11_MODULE(arco, m) {
  using namespace arco;
  using namespace arco::python;
  m.doc() = "arco: markerless motion capture of string players (docs/python.md)";
  m.attr("__version__") = ARCO_VERSION_STRING;

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
          [](const Camera& c) { return MatrixToArray(c.cam_from_world_rotation); },
          "(3, 3) rotation cam_from_world")
      .def_property_readonly(
          "t",
          [](const Camera& c) {
            const Eigen::Vector3d& t = c.cam_from_world_translation;
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
              StatusOr<CalibrationFormat> parsed = CalibrationFormatFromFlag(format);
              CheckValid(parsed.status());
              f = *parsed;
            }
            const Status saved = SaveCalibration(path.string(), c.calibration.rig, f);
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

  m.def("track_pitch",
        &TrackPitch,
        "samples"_a,
        "sample_rate"_a,
        "fps"_a = 30.0,
        "instrument"_a = "cello",
        py::kw_only(),
        "start_s"_a = 0.0,
        "frames"_a = -1,
        "hops_per_frame"_a = 0,
        "a4_hz"_a = 440.0,
        "min_f0_hz"_a = 0.0,
        "max_f0_hz"_a = 0.0,
        R"(Pitch of float samples ((frames,) or (frames, channels), mixed down as `arco pitch` does)
at video-frame times: the rows of `arco pitch`.

Returns a dict of columns frame, time_s, f0_hz (0 unvoiced), confidence, voiced.)");

  py::class_<InstrumentModel, std::shared_ptr<InstrumentModel>>(
      m, "Instrument", "An instrument model")
      .def(py::init([](const std::string& name, double a4_hz) {
             return std::const_pointer_cast<InstrumentModel>(MakeInstrument(name, a4_hz));
           }),
           "name"_a = "cello",
           "a4_hz"_a = 440.0)
      .def_property_readonly("name", &InstrumentModel::name)
      .def_property_readonly("num_strings", &InstrumentModel::num_strings)
      .def_property_readonly("string_length_mm", &InstrumentModel::string_length_mm)
      .def_property_readonly("nut_spacing_mm", &InstrumentModel::nut_spacing_mm)
      .def_property_readonly("bridge_spacing_mm", &InstrumentModel::bridge_spacing_mm)
      .def("open_hz", &InstrumentModel::open_hz, "string"_a)
      .def("max_hz", &InstrumentModel::max_hz, "string"_a)
      .def("open_note_name", &InstrumentModel::open_note_name, "string"_a)
      .def("__repr__", [](const InstrumentModel& i) {
        return std::string("<arco.Instrument ") + i.name() + ">";
      });

  const ContactOptions c;
  m.def("contact_point",
        &ContactPointPy,
        "instrument"_a,
        "string"_a,
        "f0_hz"_a,
        py::kw_only(),
        "open_tolerance_cents"_a = c.open_tolerance_cents,
        "range_tolerance_cents"_a = c.range_tolerance_cents,
        "physical_correction"_a = c.physical_correction,
        R"(Where a finger stops `string` (1 = highest) to sound f0_hz (scalar or array).

instrument: an arco.Instrument or a name. Returns a dict: kind, stopped, string, f0_hz,
cents_from_open, stop_from_bridge_mm, contact_from_bridge_mm, fraction_from_bridge.)");

  py::class_<hand::HandModel, std::shared_ptr<hand::HandModel>>(
      m, "HandModel", "arco's 21-keypoint hand model (docs/hand.md)")
      .def(py::init([](const std::string& side, const py::object& bone_lengths_mm) {
             return std::const_pointer_cast<hand::HandModel>(MakeHandModel(side, bone_lengths_mm));
           }),
           "side"_a = "left",
           "bone_lengths_mm"_a = py::none(),
           "The average adult hand, or one with these (21,) bone lengths (entry 0 unused)")
      .def_property_readonly("side",
                             [](const hand::HandModel& h) { return hand::HandSideName(h.side()); })
      .def_property_readonly("bone_lengths_mm",
                             [](const hand::HandModel& h) {
                               const hand::BoneLengthsMm l = h.bone_lengths_mm();
                               return VectorToArray(std::vector<double>(l.begin(), l.end()));
                             })
      .def_property_readonly(
          "limits_rad",
          [](const hand::HandModel& h) {
            std::vector<double> v;
            for (int d = 0; d < hand::kNumJointDofs; ++d) {
              v.push_back(h.min_rad(d));
              v.push_back(h.max_rad(d));
            }
            return ToArray(std::move(v), {hand::kNumJointDofs, 2});
          },
          "(20, 2) [min, max] of each joint angle")
      .def_property_readonly_static("keypoint_names",
                                    [](const py::object&) {
                                      std::vector<std::string> names;
                                      for (int k = 0; k < hand::kNumHandKeypoints; ++k) {
                                        names.push_back(hand::KeypointName(k));
                                      }
                                      return names;
                                    })
      .def_property_readonly_static("dof_names",
                                    [](const py::object&) {
                                      std::vector<std::string> names;
                                      for (int d = 0; d < hand::kNumJointDofs; ++d) {
                                        names.push_back(hand::DofName(d));
                                      }
                                      return names;
                                    })
      .def("__repr__",
           [](const hand::HandModel& h) {
             return std::string("<arco.HandModel ") + hand::HandSideName(h.side()) + ">";
           })
      .def("forward_kinematics",
           &ForwardKinematicsPy,
           "params"_a,
           "(..., 26) hand_params rows -> (..., 21, 3) keypoints in world mm (NaN rows: NaN)")
      .def("fingertip_ik",
           &FingertipIkPy,
           "params"_a,
           "finger"_a,
           "target_mm"_a,
           py::kw_only(),
           "joints"_a = "pip_dip",
           "reference_weight_mm_per_rad"_a = hand::FingerIkOptions().reference_weight_mm_per_rad,
           "max_change_deg"_a = hand::FingerIkOptions().max_change_deg,
           "exact_reach"_a = hand::FingerIkOptions().exact_reach,
           "max_iterations"_a = hand::FingerIkOptions().max_iterations,
           R"(Bounded IK: move `finger` (0 thumb .. 4 little)'s tip to target_mm, only the
`joints` (pip_dip | mcp_flex_pip_dip | all) free, within the joint limits.

Returns a dict: params (26,), converged, iterations, initial_distance_mm, final_distance_mm,
active_limit_dofs, step_limited, termination.)");

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

  m.def("read_result",
        &ReadResult,
        "dir"_a,
        R"(Reads an `arco run` result folder.

Returns a dict: result (result.json), points3d {stage: (F, P, 3)}, keypoint_names {stage: the
P names}, contacts {method: columns},
pitch (columns of pitch.csv or None), instrument (strings_mm (F, S, 2, 3), keypoints_mm,
name, a4_hz, world_units_per_mm; or None), hand_params ((F, 26)) and bone_lengths_mm ((21,)) of
the fitted left hand (or None).)");
}
