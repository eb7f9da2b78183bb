// JSON calibrations <-> Rig (conventions in calibration_io.h).
// SPD JSON:
//   {"cam0": {"K": [9], "R": [9], "T": [3], "imgSize": [w, h],
//             "distort": [k1, k2, p1, p2, k3]}, ...}
// K in Metashape's pixel origin (corner), `distort` in Metashape's p1/p2 order.
// arco JSON: {"format": "arco-calibration", "version": 1, "units": "...",
//   "cameras": [{"name", "serial", "width", "height", "K", "R", "t", "distortion"}]}
// in arco's own (OpenCV) convention.
#include <algorithm>
#include <cmath>
#include <set>

#include "arco/camera/calibration_io.h"
#include "arco/util/json_io.h"

namespace arco {
namespace {

// Flattens a numeric array; also accepts rows (e.g. 3x3 written as [[..], [..], [..]]).
Status FlattenNumbers(const Json& value, const std::string& what, std::vector<double>* out) {
  if (!value.is_array()) return Status::Error(what + " is not an array of numbers");
  for (const Json& item : value) {
    if (item.is_number()) {
      out->push_back(item.get<double>());
      continue;
    }
    if (!item.is_array()) {
      return Status::Error(what + " contains a non-number (" + std::string(item.type_name()) + ")");
    }
    for (const Json& v : item) {
      if (!v.is_number()) {
        return Status::Error(what + " contains a non-number (" + std::string(v.type_name()) + ")");
      }
      out->push_back(v.get<double>());
    }
  }
  return Status::Ok();
}

Status ReadArray(const Json& object,
                 const char* key,
                 const std::string& who,
                 std::vector<size_t> allowed_sizes,
                 std::vector<double>* out) {
  out->clear();
  auto it = object.find(key);
  if (it == object.end()) return Status::Error(who + " has no \"" + key + "\"");
  const std::string what = who + " \"" + key + "\"";
  ARCO_RETURN_IF_ERROR(FlattenNumbers(*it, what, out));
  if (std::find(allowed_sizes.begin(), allowed_sizes.end(), out->size()) == allowed_sizes.end()) {
    return Status::Error(what + " has " + std::to_string(out->size()) + " numbers, expected " +
                         std::to_string(allowed_sizes.front()));
  }
  for (double v : *out) {
    if (!std::isfinite(v)) return Status::Error(what + " contains a non-finite number");
  }
  return Status::Ok();
}

// Sort key that puts "cam2" before "cam10"; other names after, alphabetically.
std::pair<long, std::string> NameOrder(const std::string& name) {
  if (name.size() > 3 && name.size() < 12 && name.compare(0, 3, "cam") == 0 &&
      std::all_of(name.begin() + 3, name.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return {std::stol(name.substr(3)), name};
  }
  return {1L << 40, name};
}

StatusOr<Camera> ReadSpdCamera(const std::string& name, const Json& j) {
  const std::string who = "camera \"" + name + "\"";
  if (!j.is_object()) return Status::Error(who + " is not an object");
  Camera cam;
  cam.name = name;
  cam.serial = SpdSerialForName(name);
  std::vector<double> k, r, t, size, dist;
  ARCO_RETURN_IF_ERROR(ReadArray(j, "K", who, {9}, &k));
  ARCO_RETURN_IF_ERROR(ReadArray(j, "R", who, {9}, &r));
  ARCO_RETURN_IF_ERROR(ReadArray(j, "T", who, {3}, &t));
  ARCO_RETURN_IF_ERROR(ReadArray(j, "imgSize", who, {2}, &size));
  if (j.contains("distort")) {
    ARCO_RETURN_IF_ERROR(ReadArray(j, "distort", who, {5, 4}, &dist));
  }
  if (k[3] != 0 || k[6] != 0 || k[7] != 0 || k[8] != 1) {
    return Status::Error(who +
                         " \"K\" is not an intrinsic matrix (row 3 must be 0 0 1, K[1][0] 0)");
  }
  for (double s : size) {
    if (s != std::floor(s) || s < 1 || s > 1e6) {
      return Status::Error(who + " \"imgSize\" must hold two positive integers");
    }
  }
  cam.width = static_cast<int>(size[0]);
  cam.height = static_cast<int>(size[1]);
  cam.fx = k[0];
  cam.skew = k[1];
  cam.fy = k[4];
  cam.cx = k[2] - 0.5;  // Metashape corner origin -> OpenCV pixel centre
  cam.cy = k[5] - 0.5;
  if (!dist.empty()) {
    cam.distortion.k1 = dist[0];
    cam.distortion.k2 = dist[1];
    cam.distortion.p1 = dist[3];  // Metashape p2 plays OpenCV's p1 role
    cam.distortion.p2 = dist[2];
    cam.distortion.k3 = dist.size() == 5 ? dist[4] : 0.0;
  }
  cam.cam_from_world.rotation = Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(r.data());
  cam.cam_from_world.translation = Eigen::Vector3d(t[0], t[1], t[2]);
  ARCO_RETURN_IF_ERROR(ValidateCamera(cam));
  return cam;
}

}  // namespace

StatusOr<Calibration> ParseSpdJson(const std::string& text, const std::string& source) {
  ARCO_ASSIGN_OR_RETURN(Json json, ParseJsonLenient(text, source));
  if (!json.is_object()) return Status::Error(source + ": SPD calibration must be a JSON object");
  std::vector<std::string> names;
  for (auto it = json.begin(); it != json.end(); ++it) names.push_back(it.key());
  std::sort(names.begin(), names.end(), [](const std::string& a, const std::string& b) {
    return NameOrder(a) < NameOrder(b);
  });
  Calibration result;
  result.format = CalibrationFormat::kSpdJson;
  result.rig.units = "metashape";
  for (const std::string& name : names) {
    auto cam = ReadSpdCamera(name, json[name]);
    if (!cam.ok()) return cam.status().WithContext(source);
    result.rig.cameras.push_back(std::move(cam).value());
  }
  Status valid = ValidateRig(result.rig);
  if (!valid.ok()) return valid.WithContext(source);
  return result;
}

StatusOr<std::string> WriteSpdJson(const Rig& rig) {
  ARCO_RETURN_IF_ERROR(ValidateRig(rig));
  nlohmann::ordered_json out = nlohmann::ordered_json::object();
  // Keys: "camN" names as they are, then SPD names of known serials, then the
  // smallest free "camN" for the rest.
  std::vector<std::string> keys(rig.cameras.size());
  std::set<std::string> used;
  for (int pass = 0; pass < 3; ++pass) {
    int next_free = 0;
    for (size_t i = 0; i < rig.cameras.size(); ++i) {
      const Camera& cam = rig.cameras[i];
      if (!keys[i].empty()) continue;
      std::string key;
      if (pass == 0 && NameOrder(cam.name).first < (1L << 40)) key = cam.name;
      if (pass == 1) key = SpdNameForSerial(cam.serial);
      if (pass == 2) {
        while (used.count("cam" + std::to_string(next_free))) ++next_free;
        key = "cam" + std::to_string(next_free);
      }
      if (key.empty()) continue;
      if (!used.insert(key).second) {
        if (pass == 0) return Status::Error("SPD JSON key '" + key + "' names two cameras");
        continue;  // a serial's SPD name already taken: fall through to a free name
      }
      keys[i] = key;
    }
  }
  for (size_t i = 0; i < rig.cameras.size(); ++i) {
    const Camera& cam = rig.cameras[i];
    const std::string& key = keys[i];
    const Eigen::Matrix3d& r = cam.cam_from_world.rotation;
    const Eigen::Vector3d& t = cam.cam_from_world.translation;
    const Distortion& d = cam.distortion;
    out[key] = {
        {"K", {cam.fx, cam.skew, cam.cx + 0.5, 0, cam.fy, cam.cy + 0.5, 0, 0, 1}},
        {"R", {r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2)}},
        {"T", {t[0], t[1], t[2]}},
        {"imgSize", {static_cast<double>(cam.width), static_cast<double>(cam.height)}},
        {"distort", {d.k1, d.k2, d.p2, d.p1, d.k3}},  // Metashape p1/p2 order
    };
  }
  return out.dump(4) + "\n";
}

namespace {

constexpr const char* kArcoFormat = "arco-calibration";

StatusOr<Camera> ReadArcoCamera(size_t index, const Json& j) {
  std::string who = "camera " + std::to_string(index);
  if (!j.is_object()) return Status::Error(who + " is not an object");
  Camera cam;
  auto name = j.find("name");
  if (name == j.end() || !name->is_string()) return Status::Error(who + " has no string \"name\"");
  cam.name = name->get<std::string>();
  who = "camera \"" + cam.name + "\"";
  if (auto serial = j.find("serial"); serial != j.end()) {
    if (!serial->is_string()) return Status::Error(who + " \"serial\" is not a string");
    cam.serial = serial->get<std::string>();
  }
  for (const char* key : {"width", "height"}) {
    auto it = j.find(key);
    if (it == j.end() || !it->is_number_integer()) {
      return Status::Error(who + " has no integer \"" + key + "\"");
    }
    const int64_t v = it->get<int64_t>();
    if (v < 1 || v > 1000000) return Status::Error(who + " \"" + key + "\" is out of range");
    (std::string(key) == "width" ? cam.width : cam.height) = static_cast<int>(v);
  }
  std::vector<double> k, r, t;
  ARCO_RETURN_IF_ERROR(ReadArray(j, "K", who, {9}, &k));
  ARCO_RETURN_IF_ERROR(ReadArray(j, "R", who, {9}, &r));
  ARCO_RETURN_IF_ERROR(ReadArray(j, "t", who, {3}, &t));
  if (k[3] != 0 || k[6] != 0 || k[7] != 0 || k[8] != 1) {
    return Status::Error(who +
                         " \"K\" is not an intrinsic matrix (row 3 must be 0 0 1, K[1][0] 0)");
  }
  cam.fx = k[0];
  cam.skew = k[1];
  cam.cx = k[2];
  cam.fy = k[4];
  cam.cy = k[5];
  cam.cam_from_world.rotation = Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(r.data());
  cam.cam_from_world.translation = Eigen::Vector3d(t[0], t[1], t[2]);
  if (auto dist = j.find("distortion"); dist != j.end()) {
    if (!dist->is_object()) return Status::Error(who + " \"distortion\" is not an object");
    Distortion& d = cam.distortion;
    for (auto [key, out] : {std::pair<const char*, double*>{"k1", &d.k1},
                            {"k2", &d.k2},
                            {"k3", &d.k3},
                            {"p1", &d.p1},
                            {"p2", &d.p2}}) {
      auto it = dist->find(key);
      if (it == dist->end()) continue;
      if (!it->is_number()) {
        return Status::Error(who + " distortion \"" + key + "\" is not a number");
      }
      *out = it->get<double>();
    }
    for (auto it = dist->begin(); it != dist->end(); ++it) {
      const std::string& key = it.key();
      if (key != "k1" && key != "k2" && key != "k3" && key != "p1" && key != "p2") {
        return Status::Error(who + " has an unsupported distortion term \"" + key + "\"");
      }
    }
  }
  ARCO_RETURN_IF_ERROR(ValidateCamera(cam));
  return cam;
}

}  // namespace

StatusOr<Calibration> ParseArcoJson(const std::string& text, const std::string& source) {
  ARCO_ASSIGN_OR_RETURN(Json json, ParseJsonLenient(text, source));
  auto fail = [&](const std::string& message) { return Status::Error(source + ": " + message); };
  if (!json.is_object()) return fail("arco calibration must be a JSON object");
  if (auto format = json.find("format"); format != json.end() && *format != kArcoFormat) {
    return fail("\"format\" is not \"" + std::string(kArcoFormat) + "\"");
  }
  if (auto version = json.find("version"); version != json.end() && *version != 1) {
    return fail("unsupported \"version\" (this arco reads version 1)");
  }
  auto cameras = json.find("cameras");
  if (cameras == json.end() || !cameras->is_array()) return fail("no \"cameras\" array");
  Calibration result;
  result.format = CalibrationFormat::kArcoJson;
  if (auto units = json.find("units"); units != json.end()) {
    if (!units->is_string()) return fail("\"units\" is not a string");
    result.rig.units = units->get<std::string>();
  }
  for (size_t i = 0; i < cameras->size(); ++i) {
    auto cam = ReadArcoCamera(i, (*cameras)[i]);
    if (!cam.ok()) return cam.status().WithContext(source);
    result.rig.cameras.push_back(std::move(cam).value());
  }
  Status valid = ValidateRig(result.rig);
  if (!valid.ok()) return valid.WithContext(source);
  return result;
}

StatusOr<std::string> WriteArcoJson(const Rig& rig) {
  ARCO_RETURN_IF_ERROR(ValidateRig(rig));
  nlohmann::ordered_json out;
  out["format"] = kArcoFormat;
  out["version"] = 1;
  out["units"] = rig.units;
  out["cameras"] = nlohmann::ordered_json::array();
  for (const Camera& cam : rig.cameras) out["cameras"].push_back(CameraToJson(cam));
  return out.dump(2) + "\n";
}

}  // namespace arco
