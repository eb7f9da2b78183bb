// glTF 2.0 binary (.glb) writer (Khronos glTF 2.0 specification): a JSON chunk and one
// BIN chunk. The scene:
//   "arco" (root)
//     "keypoints": one node per keypoint, named by it, a small octahedron mesh, its
//                  translation animated per frame (metres, LINEAR) and its scale (STEP):
//                  1 where the point exists, 0 in a gap (the translation holds)
//     "instrument": one node per string ("string1" = highest .. "stringN") and "bow"
//                  (frog -> tip): a unit line along +Z, translation at the nut (frog),
//                  rotation onto the string, scale (1, 1, length)
// The per-frame contact marker is the keypoint node "contact" (hidden without contact).
#include <Eigen/Geometry>
#include <cmath>
#include <cstring>
#include <functional>

#include "arco/export/export.h"
#include "arco/util/json_io.h"

namespace arco::exporter {
namespace {

constexpr int kFloat = 5126;
constexpr int kArrayBuffer = 34962;

class GlbBuilder {
 public:
  // Appends floats as a new bufferView + accessor; returns the accessor index.
  int AddAccessor(const std::vector<float>& values,
                  const char* type,
                  int components,
                  bool with_bounds,
                  bool vertex_target = false) {
    while (bin_.size() % 4 != 0) bin_.push_back('\0');
    const size_t offset = bin_.size();
    bin_.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(float));
    Json view = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", values.size() * 4}};
    if (vertex_target) view["target"] = kArrayBuffer;
    views_.push_back(view);
    Json accessor = {{"bufferView", views_.size() - 1},
                     {"componentType", kFloat},
                     {"count", values.size() / components},
                     {"type", type}};
    if (with_bounds) {
      std::vector<float> lo(components, INFINITY), hi(components, -INFINITY);
      for (size_t i = 0; i < values.size(); ++i) {
        lo[i % components] = std::min(lo[i % components], values[i]);
        hi[i % components] = std::max(hi[i % components], values[i]);
      }
      accessor["min"] = lo;
      accessor["max"] = hi;
    }
    accessors_.push_back(accessor);
    return static_cast<int>(accessors_.size()) - 1;
  }

  std::string Finish(Json gltf) {
    while (bin_.size() % 4 != 0) bin_.push_back('\0');
    gltf["buffers"] = Json::array({{{"byteLength", bin_.size()}}});
    gltf["bufferViews"] = views_;
    gltf["accessors"] = accessors_;
    std::string json = gltf.dump();
    while (json.size() % 4 != 0) json.push_back(' ');
    std::string out;
    auto u32 = [&out](uint32_t v) {
      for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
    };
    u32(0x46546C67);  // "glTF"
    u32(2);
    u32(static_cast<uint32_t>(12 + 8 + json.size() + 8 + bin_.size()));
    u32(static_cast<uint32_t>(json.size()));
    u32(0x4E4F534A);  // "JSON"
    out += json;
    u32(static_cast<uint32_t>(bin_.size()));
    u32(0x004E4942);  // "BIN\0"
    out += bin_;
    return out;
  }

 private:
  std::string bin_;
  Json views_ = Json::array();
  Json accessors_ = Json::array();
};

// Values per frame with gaps filled by the nearest earlier frame (the first valid one
// before it); `valid` is false everywhere when no frame has one.
template <typename Get>
std::vector<Eigen::Vector3d> HoldGaps(int64_t frames, Get get, std::vector<bool>& valid) {
  std::vector<Eigen::Vector3d> out(frames, Eigen::Vector3d::Zero());
  valid.assign(frames, false);
  Eigen::Vector3d last = Eigen::Vector3d::Zero();
  bool have = false;
  for (int64_t f = 0; f < frames; ++f) {
    const Eigen::Vector3d x = get(f);
    if (x.allFinite()) {
      valid[f] = true;
      if (!have) {
        for (int64_t g = 0; g < f; ++g) out[g] = x;
      }
      last = x;
      have = true;
    }
    out[f] = last;
  }
  return out;
}

}  // namespace

std::string GlbBytes(const ExportData& data) {
  constexpr double kMetresPerMm = 1e-3;
  const int64_t frames = std::max<int64_t>(data.frames(), 1);
  GlbBuilder b;
  Json nodes = Json::array();
  Json samplers = Json::array();
  Json channels = Json::array();

  std::vector<float> times(frames);
  for (int64_t f = 0; f < frames; ++f) times[f] = static_cast<float>(f / data.fps);
  const int time_accessor = b.AddAccessor(times, "SCALAR", 1, true);

  auto animate = [&](int node,
                     const char* path,
                     const std::vector<float>& values,
                     const char* type,
                     int components,
                     const char* interpolation) {
    const int output = b.AddAccessor(values, type, components, false);
    samplers.push_back(
        {{"input", time_accessor}, {"output", output}, {"interpolation", interpolation}});
    channels.push_back(
        {{"sampler", samplers.size() - 1}, {"target", {{"node", node}, {"path", path}}}});
  };

  // Meshes: 0 an octahedron marker of radius 5 mm, 1 a unit line along +Z.
  const float r = 0.005f;
  const std::vector<float> octahedron = {r, 0, 0, 0, r, 0, 0, 0, r, -r, 0, 0, 0, -r, 0, 0, 0, -r};
  std::vector<float> marker;
  const int faces[8][3] = {
      {0, 1, 2}, {1, 3, 2}, {3, 4, 2}, {4, 0, 2}, {1, 0, 5}, {3, 1, 5}, {4, 3, 5}, {0, 4, 5}};
  for (const auto& face : faces) {
    for (int v : face) {
      for (int k = 0; k < 3; ++k) marker.push_back(octahedron[3 * v + k]);
    }
  }
  const int marker_positions = b.AddAccessor(marker, "VEC3", 3, true, true);
  const int line_positions = b.AddAccessor({0, 0, 0, 0, 0, 1}, "VEC3", 3, true, true);
  Json meshes = Json::array(
      {{{"name", "marker"}, {"primitives", {{{"attributes", {{"POSITION", marker_positions}}}}}}},
       {{"name", "unit_line"},
        {"primitives", {{{"attributes", {{"POSITION", line_positions}}}, {"mode", 1}}}}}});

  nodes.push_back({{"name", "arco"}, {"children", {1, 2}}});
  nodes.push_back({{"name", "keypoints"}});
  nodes.push_back({{"name", "instrument"}});
  Json keypoint_children = Json::array();
  for (int p = 0; p < data.points(); ++p) {
    std::vector<bool> valid;
    const auto xs = HoldGaps(
        frames, [&](int64_t f) { return data.At(f, p); }, valid);
    const int node = static_cast<int>(nodes.size());
    nodes.push_back({{"name", data.keypoint_names[p]}, {"mesh", 0}});
    keypoint_children.push_back(node);
    std::vector<float> t(3 * frames), s(3 * frames);
    bool gaps = false;
    for (int64_t f = 0; f < frames; ++f) {
      for (int k = 0; k < 3; ++k) {
        t[3 * f + k] = static_cast<float>(xs[f][k] * kMetresPerMm);
        s[3 * f + k] = valid[f] ? 1.0f : 0.0f;
      }
      gaps = gaps || !valid[f];
    }
    animate(node, "translation", t, "VEC3", 3, "LINEAR");
    if (gaps) animate(node, "scale", s, "VEC3", 3, "STEP");
  }
  nodes[1]["children"] = keypoint_children;

  // Segments: the strings (nut -> bridge) and the bow (frog -> tip).
  struct Segment {
    std::string name;
    std::function<Eigen::Vector3d(int64_t)> from, to;
  };
  std::vector<Segment> segments;
  if (!data.strings_mm.shape.empty()) {
    const auto& sm = data.strings_mm;
    for (int64_t s = 0; s < sm.shape[1]; ++s) {
      auto end = [&sm, s](int e) {
        return [&sm, s, e](int64_t f) {
          return Eigen::Vector3d(sm.at(f, s, e, 0), sm.at(f, s, e, 1), sm.at(f, s, e, 2));
        };
      };
      segments.push_back({"string" + std::to_string(s + 1), end(0), end(1)});
    }
  }
  const int frog = data.Find("frog"), tip = data.Find("tip");
  if (frog >= 0 && tip >= 0) {
    segments.push_back({"bow",
                        [&](int64_t f) { return data.At(f, frog); },
                        [&](int64_t f) { return data.At(f, tip); }});
  }
  Json instrument_children = Json::array();
  for (const Segment& seg : segments) {
    std::vector<bool> valid;
    const auto from = HoldGaps(
        frames,
        [&](int64_t f) {
          const Eigen::Vector3d a = seg.from(f), c = seg.to(f);
          return (a.allFinite() && c.allFinite() && (c - a).norm() > 1e-9)
                     ? a
                     : Eigen::Vector3d::Constant(NAN);
        },
        valid);
    std::vector<bool> valid_to;
    const auto to = HoldGaps(
        frames,
        [&](int64_t f) {
          const Eigen::Vector3d a = seg.from(f), c = seg.to(f);
          return (a.allFinite() && c.allFinite() && (c - a).norm() > 1e-9)
                     ? c
                     : Eigen::Vector3d::Constant(NAN);
        },
        valid_to);
    const int node = static_cast<int>(nodes.size());
    nodes.push_back({{"name", seg.name}, {"mesh", 1}});
    instrument_children.push_back(node);
    std::vector<float> t(3 * frames), q(4 * frames), s(3 * frames);
    for (int64_t f = 0; f < frames; ++f) {
      Eigen::Vector3d d = to[f] - from[f];
      double length = d.norm();
      if (!(length > 1e-9)) {
        d = Eigen::Vector3d::UnitZ();
        length = 1;
      }
      const Eigen::Quaterniond rot =
          Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), d).normalized();
      const float shown = valid[f] ? 1.0f : 0.0f;
      for (int k = 0; k < 3; ++k) t[3 * f + k] = static_cast<float>(from[f][k] * kMetresPerMm);
      q[4 * f + 0] = static_cast<float>(rot.x());
      q[4 * f + 1] = static_cast<float>(rot.y());
      q[4 * f + 2] = static_cast<float>(rot.z());
      q[4 * f + 3] = static_cast<float>(rot.w());
      s[3 * f + 0] = shown;
      s[3 * f + 1] = shown;
      s[3 * f + 2] = static_cast<float>(length * kMetresPerMm) * shown;
    }
    animate(node, "translation", t, "VEC3", 3, "LINEAR");
    animate(node, "rotation", q, "VEC4", 4, "LINEAR");
    animate(node, "scale", s, "VEC3", 3, "LINEAR");
  }
  if (!instrument_children.empty()) nodes[2]["children"] = instrument_children;

  Json gltf = {
      {"asset", {{"version", "2.0"}, {"generator", "arco export"}}},
      {"scene", 0},
      {"scenes", {{{"name", "arco " + data.method}, {"nodes", {0}}}}},
      {"nodes", nodes},
      {"meshes", meshes},
      {"animations", {{{"name", data.method}, {"samplers", samplers}, {"channels", channels}}}}};
  return b.Finish(gltf);
}

}  // namespace arco::exporter
