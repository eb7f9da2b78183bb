// arco.read_result: an `arco run` result folder as numpy arrays.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "arco/pipeline/result_folder.h"
#include "arco/python/bindings.h"
#include "arco/refine/contacts_csv.h"
#include "arco/util/npy.h"

namespace arco::python {

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
  out["result"] = JsonToPython(manifest);
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
  out["rest_points_mm"] = py::none();
  if (std::filesystem::exists(folder.HandParamsPath(), ec)) {
    // The fitted model's rest pose (made from the bone lengths for older results).
    const pipeline::HandRecord hand = ValueOrRaise(folder.ReadHand(), folder.HandParamsPath());
    py::array_t<double> rest({hand::kNumHandKeypoints, 3});
    auto o = rest.mutable_unchecked<2>();
    for (int k = 0; k < hand::kNumHandKeypoints; ++k) {
      for (int c = 0; c < 3; ++c) o(k, c) = hand.rest_points_mm[static_cast<size_t>(k)][c];
    }
    out["rest_points_mm"] = rest;
    out["hand_params"] =
        ToArray(ValueOrRaise(ReadNpy<double>(folder.HandParamsPath()), folder.HandParamsPath()));
    out["bone_lengths_mm"] =
        ToArray(ValueOrRaise(ReadNpy<double>(folder.BoneLengthsPath()), folder.BoneLengthsPath()));
  }
  return out;
}

void BindResult(py::module_& m) {
  m.def("read_result",
        &ReadResult,
        "dir"_a,
        R"(Reads an `arco run` result folder.

Returns a dict: result (result.json), points3d {stage: (F, P, 3)}, keypoint_names {stage: the
P names}, contacts {method: columns},
pitch (columns of pitch.csv or None), instrument (strings_mm (F, S, 2, 3), keypoints_mm,
name, a4_hz, world_units_per_mm; or None), hand_params ((F, 26)), bone_lengths_mm ((21,)) and
rest_points_mm ((21, 3): HandModel("left", rest_points_mm=...) is the fitted model) of the
fitted left hand (or None).)");
}

}  // namespace arco::python
