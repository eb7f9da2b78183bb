// Agisoft Metashape camera XML -> Rig (conventions in calibration_io.h).
//
// Layout read (Metashape 1.x/2.x "Export Cameras", XML):
//   <document><chunk>
//     <sensors><sensor id type="frame"><resolution width height/>
//       <calibration type="frame" class="adjusted"><f/><cx/><cy/><b1/><b2/><k1/>..<p2/>
//     <components><component id><transform>?            (Metashape 2)
//     <cameras>[<group>]<camera id sensor_id component_id label><transform>16 numbers
//     <transform><rotation/><translation/><scale/></transform>?   (chunk -> world)
#include <tinyxml2.h>

#include <charconv>
#include <cmath>
#include <map>
#include <optional>

#include "arco/camera/calibration_io.h"

namespace arco {
namespace {

using tinyxml2::XMLElement;

// Whitespace-separated finite numbers; nullopt on anything else.
std::optional<std::vector<double>> ParseNumbers(const char* text) {
  std::vector<double> values;
  if (text == nullptr) return values;
  const char* p = text;
  const char* end = text + std::char_traits<char>::length(text);
  auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
  while (true) {
    while (p < end && is_space(*p)) ++p;
    if (p == end) break;
    double v = 0;
    auto [next, ec] = std::from_chars(p, end, v);
    if (ec != std::errc() || (next < end && !is_space(*next)) || !std::isfinite(v)) {
      return std::nullopt;
    }
    values.push_back(v);
    p = next;
  }
  return values;
}

// Reads exactly `count` numbers from the text of `element`.
Status ReadNumbers(const XMLElement* element,
                   size_t count,
                   const std::string& what,
                   std::vector<double>* out) {
  const char* text = element->GetText();
  auto values = ParseNumbers(text);
  if (!values) {
    std::string shown = text ? text : "";
    if (shown.size() > 40) shown = shown.substr(0, 40) + "...";
    return Status::Error(what + " is not a list of finite numbers: '" + shown + "'");
  }
  if (values->size() != count) {
    return Status::Error(what + " has " + std::to_string(values->size()) + " numbers, expected " +
                         std::to_string(count));
  }
  *out = std::move(*values);
  return Status::Ok();
}

// An optional scalar child element: `fallback` when absent.
Status ReadScalar(const XMLElement* parent,
                  const char* name,
                  const std::string& who,
                  double fallback,
                  double* out) {
  const XMLElement* e = parent->FirstChildElement(name);
  if (e == nullptr) {
    *out = fallback;
    return Status::Ok();
  }
  std::vector<double> v;
  ARCO_RETURN_IF_ERROR(ReadNumbers(e, 1, who + " <" + name + ">", &v));
  *out = v[0];
  return Status::Ok();
}

Status ReadIntAttribute(const XMLElement* e, const char* name, const std::string& who, int* out) {
  const char* text = e->Attribute(name);
  if (text == nullptr) return Status::Error(who + " has no '" + name + "' attribute");
  const char* end = text + std::char_traits<char>::length(text);
  auto [next, ec] = std::from_chars(text, end, *out);
  if (ec != std::errc() || next != end) {
    return Status::Error(who + " has a non-integer '" + name + "' attribute: '" + text + "'");
  }
  return Status::Ok();
}

// Intrinsics of one sensor in arco's convention (pose fields unused).
StatusOr<Camera> ReadSensor(const XMLElement* sensor,
                            const std::string& who,
                            std::vector<std::string>* warnings) {
  const char* type = sensor->Attribute("type");
  if (type != nullptr && std::string(type) != "frame") {
    return Status::Error(who + ": sensor type '" + type + "' is not supported (only 'frame')");
  }
  const XMLElement* calibration = nullptr;
  for (const XMLElement* c = sensor->FirstChildElement("calibration"); c;
       c = c->NextSiblingElement("calibration")) {
    const char* cls = c->Attribute("class");
    if (calibration == nullptr || (cls != nullptr && std::string(cls) == "adjusted")) {
      calibration = c;
    }
  }
  if (calibration == nullptr) return Status::Error(who + " has no <calibration>");
  const char* cls = calibration->Attribute("class");
  if (cls == nullptr || std::string(cls) != "adjusted") {
    warnings->push_back(who + " has no adjusted calibration; using '" +
                        std::string(cls ? cls : "unnamed") + "' values");
  }
  const char* ctype = calibration->Attribute("type");
  if (ctype != nullptr && std::string(ctype) != "frame") {
    return Status::Error(who + ": calibration type '" + ctype + "' is not supported");
  }
  // Image size: the calibration's own <resolution>, else the sensor's.
  const XMLElement* res = calibration->FirstChildElement("resolution");
  const XMLElement* sensor_res = sensor->FirstChildElement("resolution");
  if (res == nullptr) res = sensor_res;
  if (res == nullptr) return Status::Error(who + " has no <resolution>");
  Camera cam;
  ARCO_RETURN_IF_ERROR(ReadIntAttribute(res, "width", who + " <resolution>", &cam.width));
  ARCO_RETURN_IF_ERROR(ReadIntAttribute(res, "height", who + " <resolution>", &cam.height));
  if (sensor_res != nullptr && sensor_res != res) {
    int w = 0, h = 0;
    ARCO_RETURN_IF_ERROR(ReadIntAttribute(sensor_res, "width", who + " <resolution>", &w));
    ARCO_RETURN_IF_ERROR(ReadIntAttribute(sensor_res, "height", who + " <resolution>", &h));
    if (w != cam.width || h != cam.height) {
      return Status::Error(who + ": calibration resolution differs from the sensor resolution");
    }
  }
  if (calibration->FirstChildElement("f") == nullptr) {
    return Status::Error(who + ": calibration has no <f> (old fx/fy layouts are not supported)");
  }
  double f, cx, cy, b1, b2, k4, p3, p4;
  Distortion& d = cam.distortion;
  double ms_p1, ms_p2;
  struct Field {
    const char* name;
    double* out;
  };
  for (const Field& field : {Field{"f", &f},
                             Field{"cx", &cx},
                             Field{"cy", &cy},
                             Field{"b1", &b1},
                             Field{"b2", &b2},
                             Field{"k1", &d.k1},
                             Field{"k2", &d.k2},
                             Field{"k3", &d.k3},
                             Field{"k4", &k4},
                             Field{"p1", &ms_p1},
                             Field{"p2", &ms_p2},
                             Field{"p3", &p3},
                             Field{"p4", &p4}}) {
    ARCO_RETURN_IF_ERROR(ReadScalar(calibration, field.name, who, 0.0, field.out));
  }
  if (k4 != 0 || p3 != 0 || p4 != 0) {
    return Status::Error(who + ": k4, p3 and p4 are not supported by arco's camera model");
  }
  cam.fx = f + b1;
  cam.fy = f;
  cam.skew = b2;
  // Metashape measures pixels from the image corner; OpenCV from the first pixel's centre.
  cam.cx = 0.5 * cam.width + cx - 0.5;
  cam.cy = 0.5 * cam.height + cy - 0.5;
  d.p1 = ms_p2;
  d.p2 = ms_p1;
  return cam;
}

// A similarity world_from_chunk: x_world = scale * rotation * x_chunk + translation.
struct Similarity {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double scale = 1.0;
};

StatusOr<Similarity> ReadSimilarity(const XMLElement* transform, const std::string& who) {
  Similarity s;
  const XMLElement* rotation = transform->FirstChildElement("rotation");
  const XMLElement* translation = transform->FirstChildElement("translation");
  const XMLElement* scale = transform->FirstChildElement("scale");
  if (!rotation && !translation && !scale) {
    return Status::Error(who + " has none of <rotation>, <translation>, <scale>");
  }
  std::vector<double> v;
  if (rotation) {
    ARCO_RETURN_IF_ERROR(ReadNumbers(rotation, 9, who + " <rotation>", &v));
    s.rotation = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(v.data());
    const double err =
        (s.rotation.transpose() * s.rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (!(err < 1e-6) || !(s.rotation.determinant() > 0)) {
      return Status::Error(who + " <rotation> is not a rotation matrix");
    }
  }
  if (translation) {
    ARCO_RETURN_IF_ERROR(ReadNumbers(translation, 3, who + " <translation>", &v));
    s.translation = Eigen::Vector3d(v[0], v[1], v[2]);
  }
  if (scale) {
    ARCO_RETURN_IF_ERROR(ReadNumbers(scale, 1, who + " <scale>", &v));
    if (!(v[0] > 0)) return Status::Error(who + " <scale> must be positive");
    s.scale = v[0];
  }
  return s;
}

// "camera_21334181_1" -> "21334181"; empty when the label has another form.
std::string SerialFromLabel(const std::string& label) {
  const std::string prefix = "camera_";
  if (label.compare(0, prefix.size(), prefix) != 0) return "";
  const size_t start = prefix.size();
  const size_t underscore = label.find('_', start);
  if (underscore == std::string::npos || underscore == start) return "";
  for (size_t i = start; i < label.size(); ++i) {
    if (i != underscore && (label[i] < '0' || label[i] > '9')) return "";
  }
  if (underscore + 1 == label.size()) return "";
  return label.substr(start, underscore - start);
}

// Collects <camera> elements directly under <cameras> and inside <group>s, in file order.
void CollectCameras(const XMLElement* parent, std::vector<const XMLElement*>* out) {
  for (const XMLElement* e = parent->FirstChildElement(); e; e = e->NextSiblingElement()) {
    const std::string name = e->Name();
    if (name == "camera") out->push_back(e);
    if (name == "group") CollectCameras(e, out);
  }
}

StatusOr<Calibration> ParseChunk(const XMLElement* chunk) {
  Calibration result;
  result.format = CalibrationFormat::kMetashapeXml;
  result.rig.units = "metashape";

  std::map<int, const XMLElement*> sensors;
  if (const XMLElement* list = chunk->FirstChildElement("sensors")) {
    for (const XMLElement* s = list->FirstChildElement("sensor"); s;
         s = s->NextSiblingElement("sensor")) {
      int id = 0;
      ARCO_RETURN_IF_ERROR(ReadIntAttribute(s, "id", "a <sensor>", &id));
      if (!sensors.emplace(id, s).second) {
        return Status::Error("sensor id " + std::to_string(id) + " appears twice");
      }
    }
  }
  std::optional<Similarity> chunk_transform;
  if (const XMLElement* t = chunk->FirstChildElement("transform")) {
    ARCO_ASSIGN_OR_RETURN(chunk_transform, ReadSimilarity(t, "chunk <transform>"));
  }
  std::map<int, Similarity> component_transforms;
  if (const XMLElement* list = chunk->FirstChildElement("components")) {
    for (const XMLElement* c = list->FirstChildElement("component"); c;
         c = c->NextSiblingElement("component")) {
      const XMLElement* t = c->FirstChildElement("transform");
      if (t == nullptr) continue;
      int id = 0;
      ARCO_RETURN_IF_ERROR(ReadIntAttribute(c, "id", "a <component>", &id));
      ARCO_ASSIGN_OR_RETURN(component_transforms[id],
                            ReadSimilarity(t, "component " + std::to_string(id) + " <transform>"));
    }
  }

  std::vector<const XMLElement*> elements;
  if (const XMLElement* list = chunk->FirstChildElement("cameras")) CollectCameras(list, &elements);
  std::map<int, Camera> intrinsics;  // per sensor id, read on first use
  for (size_t i = 0; i < elements.size(); ++i) {
    const XMLElement* e = elements[i];
    const char* label = e->Attribute("label");
    std::string who = "camera " + std::to_string(i);
    if (label != nullptr) who += " ('" + std::string(label) + "')";
    const XMLElement* transform = e->FirstChildElement("transform");
    if (transform == nullptr || transform->GetText() == nullptr) {
      result.warnings.push_back(who + " has no <transform> (not aligned); skipped");
      continue;
    }
    int sensor_id = 0;
    ARCO_RETURN_IF_ERROR(ReadIntAttribute(e, "sensor_id", who, &sensor_id));
    auto sensor = sensors.find(sensor_id);
    if (sensor == sensors.end()) {
      return Status::Error(who + " refers to sensor " + std::to_string(sensor_id) +
                           ", which is not defined");
    }
    if (!intrinsics.count(sensor_id)) {
      ARCO_ASSIGN_OR_RETURN(
          intrinsics[sensor_id],
          ReadSensor(sensor->second, "sensor " + std::to_string(sensor_id), &result.warnings));
    }
    Camera cam = intrinsics[sensor_id];
    cam.name = label ? label : "camera" + std::to_string(i);
    cam.serial = SerialFromLabel(cam.name);

    std::vector<double> m;
    ARCO_RETURN_IF_ERROR(ReadNumbers(transform, 16, who + " <transform>", &m));
    const Eigen::Matrix4d chunk_from_cam =
        Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(m.data());
    if (!chunk_from_cam.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1), 1e-12)) {
      return Status::Error(who + " <transform> does not end with the row 0 0 0 1");
    }
    Similarity world_from_chunk;
    int component_id = -1;
    if (e->Attribute("component_id")) {
      ARCO_RETURN_IF_ERROR(ReadIntAttribute(e, "component_id", who, &component_id));
    }
    if (component_transforms.count(component_id)) {
      world_from_chunk = component_transforms[component_id];
    } else if (chunk_transform) {
      world_from_chunk = *chunk_transform;
    }
    // Camera centre and orientation in the world; the chunk scale only scales positions.
    const Eigen::Matrix3d world_from_cam_rotation =
        world_from_chunk.rotation * chunk_from_cam.topLeftCorner<3, 3>();
    const Eigen::Vector3d center_in_world =
        world_from_chunk.scale * world_from_chunk.rotation * chunk_from_cam.topRightCorner<3, 1>() +
        world_from_chunk.translation;
    cam.cam_from_world.rotation = world_from_cam_rotation.transpose();
    cam.cam_from_world.translation = -(cam.cam_from_world.rotation * center_in_world);
    ARCO_RETURN_IF_ERROR(ValidateCamera(cam));
    result.rig.cameras.push_back(std::move(cam));
  }
  if (result.rig.cameras.empty()) {
    return Status::Error(elements.empty() ? "no <camera> elements"
                                          : "no camera has a <transform> (none aligned)");
  }
  ARCO_RETURN_IF_ERROR(ValidateRig(result.rig));
  return result;
}

}  // namespace

StatusOr<Calibration> ParseMetashapeXml(const std::string& text, const std::string& source) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS) {
    return Status::Error(source + ": malformed XML (" + doc.ErrorStr() + ")");
  }
  const XMLElement* root = doc.RootElement();
  if (root == nullptr) return Status::Error(source + ": empty XML document");
  const XMLElement* chunk = nullptr;
  if (std::string(root->Name()) == "chunk") {
    chunk = root;
  } else if (std::string(root->Name()) == "document") {
    chunk = root->FirstChildElement("chunk");
    if (chunk && chunk->NextSiblingElement("chunk")) {
      return Status::Error(source + ": several <chunk> elements; export one chunk");
    }
  }
  if (chunk == nullptr) {
    return Status::Error(source + ": not a Metashape camera export (no <document><chunk>)");
  }
  auto result = ParseChunk(chunk);
  if (!result.ok()) return result.status().WithContext(source);
  return result;
}

}  // namespace arco
