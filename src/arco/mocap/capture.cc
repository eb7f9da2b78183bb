#include "arco/mocap/capture.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <set>

#include "arco/registry/instruments.h"
#include "arco/util/file_io.h"

namespace arco {
namespace {

namespace fs = std::filesystem;

// The registry's canonical instrument names, and "none".
const std::set<std::string>& Instruments() {
  static const std::set<std::string> k = [] {
    std::set<std::string> names = {"none"};
    for (const InstrumentInfo& info : AllInstruments()) names.insert(info.name);
    return names;
  }();
  return k;
}

// Typed field access that reports problems instead of throwing.
class Fields {
 public:
  Fields(const Json& object, std::string where) : j_(object), where_(std::move(where)) {}

  Status String(const char* key, bool required, std::string* out) const {
    const Json* v = Find(key);
    if (!v || v->is_null()) return required ? Missing(key) : Status::Ok();
    if (!v->is_string()) return Bad(key, "must be a string");
    *out = v->get<std::string>();
    return Status::Ok();
  }
  Status Number(const char* key, bool required, double* out) const {
    const Json* v = Find(key);
    if (!v || v->is_null()) return required ? Missing(key) : Status::Ok();
    if (!v->is_number()) return Bad(key, "must be a number");
    *out = v->get<double>();
    if (!std::isfinite(*out)) return Bad(key, "must be finite");
    return Status::Ok();
  }
  Status Integer(const char* key, bool required, int64_t* out) const {
    const Json* v = Find(key);
    if (!v || v->is_null()) return required ? Missing(key) : Status::Ok();
    if (!v->is_number_integer()) return Bad(key, "must be an integer");
    *out = v->get<int64_t>();
    return Status::Ok();
  }
  const Json* Find(const char* key) const {
    const auto it = j_.find(key);
    return it == j_.end() ? nullptr : &*it;
  }
  Status Missing(const char* key) const {
    return Status::Error(where_ + ": missing \"" + key + "\"");
  }
  Status Bad(const char* key, const std::string& what) const {
    return Status::Error(where_ + ": \"" + key + "\" " + what);
  }

 private:
  const Json& j_;
  std::string where_;
};

Status ParseCamera(const Json& j, const std::string& where, CaptureCamera* cam) {
  if (!j.is_object()) return Status::Error(where + ": must be an object");
  Fields f(j, where);
  ARCO_RETURN_IF_ERROR(f.String("name", true, &cam->name));
  if (cam->name.empty()) return f.Bad("name", "must not be empty");
  ARCO_RETURN_IF_ERROR(f.String("serial", false, &cam->serial));
  ARCO_RETURN_IF_ERROR(f.String("video", false, &cam->video));
  if (const Json* drops = f.Find("dropped_frames"); drops && !drops->is_null()) {
    if (!drops->is_array()) return f.Bad("dropped_frames", "must be an array of frame numbers");
    for (const Json& d : *drops) {
      if (!d.is_number_integer()) return f.Bad("dropped_frames", "must hold integers");
      cam->dropped_frames.push_back(d.get<int64_t>());
    }
    std::sort(cam->dropped_frames.begin(), cam->dropped_frames.end());
    cam->dropped_frames.erase(std::unique(cam->dropped_frames.begin(), cam->dropped_frames.end()),
                              cam->dropped_frames.end());
  }
  return Status::Ok();
}

}  // namespace

StatusOr<KeypointLayout> CaptureManifest::Layout() const {
  if (layout == "custom") {
    if (keypoint_names.empty()) return Status::Error("layout \"custom\" needs keypoint_names");
    return MakeCustomLayout("custom", keypoint_names);
  }
  const KeypointLayout* l = FindKeypointLayout(layout);
  if (!l) return Status::Error("unknown keypoint layout \"" + layout + "\"");
  return *l;
}

int CaptureManifest::FindCamera(const std::string& id) const {
  for (size_t i = 0; i < cameras.size(); ++i) {
    if (cameras[i].name == id || (!cameras[i].serial.empty() && cameras[i].serial == id)) {
      return static_cast<int>(i);
    }
  }
  return -1;
}

int64_t CaptureManifest::VideoFrameNumber(int view, int64_t global_frame) const {
  const auto& drops = cameras.at(static_cast<size_t>(view)).dropped_frames;
  const auto it = std::lower_bound(drops.begin(), drops.end(), global_frame);
  if (it != drops.end() && *it == global_frame) return -1;
  return global_frame - (it - drops.begin());
}

StatusOr<CaptureManifest> ParseCaptureManifest(const std::string& text, const std::string& source) {
  ARCO_ASSIGN_OR_RETURN(Json j, ParseJsonLenient(text, source));
  if (!j.is_object()) return Status::Error(source + ": a capture manifest must be a JSON object");
  Fields f(j, source);
  std::string format;
  ARCO_RETURN_IF_ERROR(f.String("format", true, &format));
  if (format != "arco-capture") {
    return Status::Error(source + ": \"format\" must be \"arco-capture\", not \"" + format + "\"");
  }
  CaptureManifest m;
  int64_t version = 1;
  ARCO_RETURN_IF_ERROR(f.Integer("version", true, &version));
  if (version != 1) return f.Bad("version", "is " + std::to_string(version) + "; arco reads 1");
  m.version = 1;
  ARCO_RETURN_IF_ERROR(f.String("name", false, &m.name));
  ARCO_RETURN_IF_ERROR(f.String("instrument", false, &m.instrument));
  if (!Instruments().count(m.instrument)) {
    return f.Bad("instrument", "must be cello, violin, viola, double_bass or none");
  }
  ARCO_RETURN_IF_ERROR(f.Number("fps", true, &m.fps));
  if (!(m.fps > 0 && m.fps <= 10000)) return f.Bad("fps", "must be in (0, 10000]");
  const Json* frames = f.Find("frames");
  if (!frames || !frames->is_object()) return f.Missing("frames");
  Fields ff(*frames, source + ": frames");
  ARCO_RETURN_IF_ERROR(ff.Integer("first", true, &m.frame_first));
  ARCO_RETURN_IF_ERROR(ff.Integer("count", true, &m.frame_count));
  if (m.frame_count < 0 || m.frame_count > 100000000) {
    return ff.Bad("count", "must be in [0, 1e8]");
  }
  if (std::abs(m.frame_first) > (int64_t{1} << 40)) return ff.Bad("first", "is out of range");
  ARCO_RETURN_IF_ERROR(f.Number("tuning_a4_hz", false, &m.tuning_a4_hz));
  if (!(m.tuning_a4_hz >= 300 && m.tuning_a4_hz <= 600)) {
    return f.Bad("tuning_a4_hz", "must be in [300, 600] Hz");
  }
  ARCO_RETURN_IF_ERROR(f.String("calibration", true, &m.calibration));
  if (const Json* audio = f.Find("audio"); audio && !audio->is_null()) {
    if (!audio->is_object()) return f.Bad("audio", "must be an object {\"file\", \"offset_s\"}");
    Fields fa(*audio, source + ": audio");
    ARCO_RETURN_IF_ERROR(fa.String("file", true, &m.audio));
    ARCO_RETURN_IF_ERROR(fa.Number("offset_s", false, &m.audio_offset_s));
    ARCO_RETURN_IF_ERROR(fa.Number("sync_confidence", false, &m.audio_sync_confidence));
    if (!std::isnan(m.audio_sync_confidence) &&
        !(m.audio_sync_confidence >= 0 && m.audio_sync_confidence <= 1)) {
      return fa.Bad("sync_confidence", "must be in [0, 1]");
    }
  }
  if (const Json* k = f.Find("keypoints2d"); k && !k->is_null()) {
    if (!k->is_object()) return f.Bad("keypoints2d", "must be an object {\"file\", \"layout\"}");
    Fields fk(*k, source + ": keypoints2d");
    ARCO_RETURN_IF_ERROR(fk.String("file", true, &m.keypoints2d));
    ARCO_RETURN_IF_ERROR(fk.String("layout", true, &m.layout));
    if (const Json* names = fk.Find("names"); names && !names->is_null()) {
      if (!names->is_array()) return fk.Bad("names", "must be an array of strings");
      for (const Json& n : *names) {
        if (!n.is_string()) return fk.Bad("names", "must be an array of strings");
        m.keypoint_names.push_back(n.get<std::string>());
      }
    }
    const auto layout = m.Layout();
    if (!layout.ok()) return Status::Error(source + ": keypoints2d: " + layout.status().message());
  }
  const Json* cams = f.Find("cameras");
  if (!cams || !cams->is_array() || cams->empty()) {
    return Status::Error(source + ": \"cameras\" must be a non-empty array");
  }
  std::set<std::string> names;
  for (size_t i = 0; i < cams->size(); ++i) {
    CaptureCamera cam;
    ARCO_RETURN_IF_ERROR(
        ParseCamera((*cams)[i], source + ": cameras[" + std::to_string(i) + "]", &cam));
    if (!names.insert(cam.name).second) {
      return Status::Error(source + ": camera \"" + cam.name + "\" is listed twice");
    }
    m.cameras.push_back(std::move(cam));
  }
  return m;
}

StatusOr<CaptureManifest> ReadCaptureManifest(const std::string& capture_dir) {
  const std::string path = JoinPath(capture_dir, kCaptureManifestName);
  ARCO_ASSIGN_OR_RETURN(std::string text, ReadFileToString(path));
  return ParseCaptureManifest(text, path);
}

Json CaptureManifestToJson(const CaptureManifest& m) {
  Json j;
  j["format"] = "arco-capture";
  j["version"] = 1;
  j["name"] = m.name;
  j["instrument"] = m.instrument;
  j["fps"] = m.fps;
  j["frames"] = {{"first", m.frame_first}, {"count", m.frame_count}};
  j["tuning_a4_hz"] = m.tuning_a4_hz;
  j["calibration"] = m.calibration;
  if (!m.audio.empty()) {
    j["audio"] = {{"file", m.audio}, {"offset_s", m.audio_offset_s}};
    if (std::isfinite(m.audio_sync_confidence)) {
      j["audio"]["sync_confidence"] = m.audio_sync_confidence;
    }
  }
  if (!m.keypoints2d.empty()) {
    j["keypoints2d"] = {{"file", m.keypoints2d}, {"layout", m.layout}};
    if (m.layout == "custom") j["keypoints2d"]["names"] = m.keypoint_names;
  }
  j["cameras"] = Json::array();
  for (const auto& c : m.cameras) {
    Json cj = {{"name", c.name}};
    if (!c.serial.empty()) cj["serial"] = c.serial;
    if (!c.video.empty()) cj["video"] = c.video;
    cj["dropped_frames"] = c.dropped_frames;
    j["cameras"].push_back(cj);
  }
  return j;
}

Status WriteCaptureManifest(const std::string& capture_dir, const CaptureManifest& manifest) {
  ARCO_RETURN_IF_ERROR(MakeDirectories(capture_dir));
  return WriteJsonFile(JoinPath(capture_dir, kCaptureManifestName),
                       CaptureManifestToJson(manifest));
}

std::string ResolveCapturePath(const std::string& dir, const std::string& entry) {
  if (entry.empty() || fs::path(entry).is_absolute()) return entry;
  return JoinPath(dir, entry);
}

StatusOr<NpyArray<double>> ReadCaptureKeypoints2d(const std::string& capture_dir,
                                                  const CaptureManifest& m) {
  const std::string manifest_path = JoinPath(capture_dir, kCaptureManifestName);
  if (m.keypoints2d.empty()) {
    return Status::Error(manifest_path +
                         ": no \"keypoints2d\" entry (2D keypoints to triangulate)");
  }
  const std::string path = ResolveCapturePath(capture_dir, m.keypoints2d);
  ARCO_ASSIGN_OR_RETURN(NpyArray<double> k, ReadNpy<double>(path));
  ARCO_ASSIGN_OR_RETURN(KeypointLayout layout, m.Layout());
  const std::vector<int64_t> expected = {
      m.frame_count, static_cast<int64_t>(m.cameras.size()), layout.size(), 3};
  if (k.shape != expected) {
    auto str = [](const std::vector<int64_t>& s) {
      std::string out = "(";
      for (size_t i = 0; i < s.size(); ++i) out += (i ? ", " : "") + std::to_string(s[i]);
      return out + ")";
    };
    return Status::Error(path + ": shape " + str(k.shape) + " does not match the manifest " +
                         str(expected) + " (frames, cameras, " + layout.name + " points, 3)");
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (size_t v = 0; v < m.cameras.size(); ++v) {
    for (int64_t g : m.cameras[v].dropped_frames) {
      const int64_t f = g - m.frame_first;
      if (f < 0 || f >= m.frame_count) continue;
      for (int64_t p = 0; p < layout.size(); ++p) {
        for (int c = 0; c < 3; ++c) k.at(f, static_cast<int64_t>(v), p, c) = nan;
      }
    }
  }
  return k;
}

}  // namespace arco
