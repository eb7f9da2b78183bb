// Shared pieces of the calibration readers/writers: validation, the SPD rig
// table, the arco camera JSON object.
#include "arco/camera/calibration_io.h"

#include <cmath>
#include <cstdint>
#include <set>
#include <sstream>

namespace arco {
namespace {

// cam0..cam23 of the SPD rig, from ../shared/data/spd/README.md.
constexpr const char* kSpdSerials[] = {
    "21334181", "21334237", "21334180", "21334209", "21334208", "21334186", "21293326", "21293325",
    "21293324", "21334206", "21334220", "21334183", "21334207", "21334191", "21334184", "21334238",
    "21334221", "21334219", "21334190", "21334211", "21334218", "21334182", "21334236", "21334210",
};
constexpr int kSpdCameraCount = sizeof(kSpdSerials) / sizeof(kSpdSerials[0]);

constexpr int kMaxImageSide = 1000000;

// Names go into JSON and YAML: they must be valid UTF-8 without control characters.
bool IsPrintableUtf8(const std::string& text) {
  size_t i = 0;
  while (i < text.size()) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    int extra = 0;
    uint32_t code = 0;
    if (c < 0x80) {
      if (c < 0x20 || c == 0x7F) return false;
      ++i;
      continue;
    } else if ((c & 0xE0) == 0xC0) {
      extra = 1, code = c & 0x1F;
    } else if ((c & 0xF0) == 0xE0) {
      extra = 2, code = c & 0x0F;
    } else if ((c & 0xF8) == 0xF0) {
      extra = 3, code = c & 0x07;
    } else {
      return false;
    }
    if (i + extra >= text.size()) return false;  // truncated sequence
    for (int k = 1; k <= extra; ++k) {
      const unsigned char next = static_cast<unsigned char>(text[i + k]);
      if ((next & 0xC0) != 0x80) return false;
      code = (code << 6) | (next & 0x3F);
    }
    // Overlong forms, surrogates and values past U+10FFFF are invalid.
    static constexpr uint32_t kMin[] = {0, 0x80, 0x800, 0x10000};
    if (code < kMin[extra] || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return false;
    if (code < 0xA0) return false;  // C1 controls
    i += extra + 1;
  }
  return true;
}

bool AllFinite(std::initializer_list<double> values) {
  for (double v : values) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

}  // namespace

const char* CalibrationFormatName(CalibrationFormat format) {
  switch (format) {
    case CalibrationFormat::kMetashapeXml:
      return "metashape-xml";
    case CalibrationFormat::kSpdJson:
      return "spd-json";
    case CalibrationFormat::kArcoJson:
      return "arco-json";
    case CalibrationFormat::kOpenCvYaml:
      return "opencv-yaml";
    case CalibrationFormat::kOpenCvXml:
      return "opencv-xml";
    case CalibrationFormat::kUnknown:
      break;
  }
  return "unknown";
}

Status ValidateCamera(const Camera& camera) {
  const std::string who = "camera '" + camera.name + "'";
  if (camera.name.empty()) return Status::Error("a camera has an empty name");
  if (!IsPrintableUtf8(camera.name) || !IsPrintableUtf8(camera.serial)) {
    return Status::Error("a camera name or serial is not printable UTF-8");
  }
  if (camera.width <= 0 || camera.height <= 0 || camera.width > kMaxImageSide ||
      camera.height > kMaxImageSide) {
    return Status::Error(who + ": image size must be 1 to 1000000 px a side (got " +
                         std::to_string(camera.width) + "x" + std::to_string(camera.height) + ")");
  }
  if (!AllFinite({camera.fx, camera.fy, camera.cx, camera.cy, camera.skew})) {
    return Status::Error(who + ": intrinsics are not finite numbers");
  }
  if (!(camera.fx > 0) || !(camera.fy > 0)) {
    return Status::Error(who + ": focal lengths must be positive");
  }
  const Distortion& d = camera.distortion;
  if (!AllFinite({d.k1, d.k2, d.k3, d.p1, d.p2})) {
    return Status::Error(who + ": distortion coefficients are not finite numbers");
  }
  const Eigen::Matrix3d& r = camera.cam_from_world.rotation;
  if (!r.allFinite() || !camera.cam_from_world.translation.allFinite()) {
    return Status::Error(who + ": pose is not finite");
  }
  const double orthonormality =
      (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(orthonormality < 1e-6) || !(r.determinant() > 0)) {
    std::ostringstream os;
    os << who << ": rotation is not a proper rotation matrix (|R^T R - I| = " << orthonormality
       << ", det = " << r.determinant() << ")";
    return Status::Error(os.str());
  }
  return Status::Ok();
}

Status ValidateRig(const Rig& rig) {
  if (rig.cameras.empty()) return Status::Error("no cameras");
  std::set<std::string> names;
  for (const Camera& camera : rig.cameras) {
    ARCO_RETURN_IF_ERROR(ValidateCamera(camera));
    if (!names.insert(camera.name).second) {
      return Status::Error("camera name '" + camera.name + "' appears twice");
    }
  }
  return Status::Ok();
}

nlohmann::ordered_json CameraToJson(const Camera& camera) {
  nlohmann::ordered_json j;
  j["name"] = camera.name;
  j["serial"] = camera.serial;
  j["width"] = camera.width;
  j["height"] = camera.height;
  const Eigen::Matrix3d k = camera.K();
  auto& jk = j["K"] = nlohmann::ordered_json::array();
  auto& jr = j["R"] = nlohmann::ordered_json::array();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      jk.push_back(k(r, c));
      jr.push_back(camera.cam_from_world.rotation(r, c));
    }
  }
  auto& jt = j["t"] = nlohmann::ordered_json::array();
  for (int r = 0; r < 3; ++r) jt.push_back(camera.cam_from_world.translation[r]);
  const Distortion& d = camera.distortion;
  j["distortion"] = {{"k1", d.k1}, {"k2", d.k2}, {"k3", d.k3}, {"p1", d.p1}, {"p2", d.p2}};
  return j;
}

std::string SpdSerialForName(const std::string& name) {
  if (name.size() < 4 || name.compare(0, 3, "cam") != 0) return "";
  int index = 0;
  for (size_t i = 3; i < name.size(); ++i) {
    if (name[i] < '0' || name[i] > '9' || i - 3 >= 3) return "";
    index = index * 10 + (name[i] - '0');
  }
  if (name.size() > 4 && name[3] == '0') return "";  // "cam01" is not an SPD name
  return index < kSpdCameraCount ? kSpdSerials[index] : "";
}

std::string SpdNameForSerial(const std::string& serial) {
  for (int i = 0; i < kSpdCameraCount; ++i) {
    if (serial == kSpdSerials[i]) return "cam" + std::to_string(i);
  }
  return "";
}

}  // namespace arco
