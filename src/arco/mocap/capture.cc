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

// The value as the user wrote it, for messages ("NaN", "\"abc\"", "[1]").
std::string Written(const Json& v) {
  const std::string token = NonFiniteToken(v);
  if (!token.empty()) return token;
  std::string text = v.dump();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return text;
}

// Typed field access that reports problems instead of throwing. Messages name the file
// and the field, quoted and dotted from the top ("frames.first"), never bare: a bare
// name reads as an option field (cli/flag_names.h rewrites those into flags).
class Fields {
 public:
  Fields(const Json& object, std::string where, std::string prefix = "")
      : j_(object), where_(std::move(where)), prefix_(std::move(prefix)) {}

  Status String(const char* key, bool required, std::string* out) const {
    const Json* v = Find(key);
    if (!v || v->is_null()) return required ? Missing(key) : Status::Ok();
    if (!v->is_string() || !NonFiniteToken(*v).empty()) {
      return Bad(key, "is " + Written(*v) + "; must be a string");
    }
    *out = v->get<std::string>();
    return Status::Ok();
  }
  Status Number(const char* key, bool required, double* out) const {
    const Json* v = Find(key);
    if (!v || v->is_null()) return required ? Missing(key) : Status::Ok();
    if (!NonFiniteToken(*v).empty()) {
      return Bad(key, "is " + Written(*v) + "; must be a finite number");
    }
    if (!v->is_number()) return Bad(key, "is " + Written(*v) + "; must be a number");
    *out = v->get<double>();
    if (!std::isfinite(*out)) return Bad(key, "must be finite");
    return Status::Ok();
  }
  Status Integer(const char* key, bool required, int64_t* out) const {
    const Json* v = Find(key);
    if (!v || v->is_null()) return required ? Missing(key) : Status::Ok();
    if (!v->is_number_integer()) return Bad(key, "is " + Written(*v) + "; must be an integer");
    // A uint64 above INT64_MAX would wrap.
    if (v->is_number_unsigned() && v->get<uint64_t>() > uint64_t{INT64_MAX}) {
      return Bad(key, "is " + Written(*v) + ", out of range");
    }
    *out = v->get<int64_t>();
    return Status::Ok();
  }
  const Json* Find(const char* key) const {
    const auto it = j_.find(key);
    return it == j_.end() ? nullptr : &*it;
  }
  std::string Name(const char* key) const { return "\"" + prefix_ + key + "\""; }
  Status Missing(const char* key) const { return Status::Error(where_ + ": missing " + Name(key)); }
  Status Bad(const char* key, const std::string& what) const {
    return Status::Error(where_ + ": " + Name(key) + " " + what);
  }

 private:
  const Json& j_;
  std::string where_;
  std::string prefix_;  // "frames.", "cameras[2]."
};

Status ParseCamera(const Json& j,
                   const std::string& source,
                   const std::string& prefix,
                   CaptureCamera* cam) {
  if (!j.is_object()) return Status::Error(source + ": \"" + prefix + "\" must be an object");
  Fields f(j, source, prefix + ".");
  ARCO_RETURN_IF_ERROR(f.String("name", true, &cam->name));
  if (cam->name.empty()) return f.Bad("name", "must not be empty");
  ARCO_RETURN_IF_ERROR(f.String("serial", false, &cam->serial));
  ARCO_RETURN_IF_ERROR(f.String("video", false, &cam->video));
  int64_t rotate_deg = 0;
  ARCO_RETURN_IF_ERROR(f.Integer("rotate_deg", false, &rotate_deg));
  if (rotate_deg != 0 && rotate_deg != 90 && rotate_deg != 180 && rotate_deg != 270) {
    return f.Bad("rotate_deg", "is " + std::to_string(rotate_deg) + "; must be 0, 90, 180 or 270");
  }
  cam->rotate_deg = static_cast<int>(rotate_deg);
  ARCO_RETURN_IF_ERROR(f.Number("offset_s", false, &cam->offset_s));
  if (!(std::abs(cam->offset_s) <= kMaxCameraOffsetS)) {
    return f.Bad("offset_s",
                 "is " + Written(*f.Find("offset_s")) + "; must be in [-86400, 86400] s");
  }
  ARCO_RETURN_IF_ERROR(f.Number("drift_ppm", false, &cam->drift_ppm));
  if (!(std::abs(cam->drift_ppm) <= kMaxCameraDriftPpm)) {
    return f.Bad("drift_ppm",
                 "is " + Written(*f.Find("drift_ppm")) + "; must be in [-10000, 10000] ppm");
  }
  if (const Json* drops = f.Find("dropped_frames"); drops && !drops->is_null()) {
    if (!drops->is_array()) return f.Bad("dropped_frames", "must be an array of frame numbers");
    for (const Json& d : *drops) {
      if (!d.is_number_integer() ||
          (d.is_number_unsigned() && d.get<uint64_t>() > uint64_t{INT64_MAX})) {
        return f.Bad("dropped_frames", "holds " + Written(d) + "; must hold integer frame numbers");
      }
      cam->dropped_frames.push_back(d.get<int64_t>());
    }
    // Any order; a frame listed twice means the file's writer is broken.
    std::sort(cam->dropped_frames.begin(), cam->dropped_frames.end());
    const auto twice = std::adjacent_find(cam->dropped_frames.begin(), cam->dropped_frames.end());
    if (twice != cam->dropped_frames.end()) {
      return f.Bad("dropped_frames", "lists frame " + std::to_string(*twice) + " twice");
    }
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

double CaptureManifest::CameraFrameAt(int view, double capture_frame) const {
  const CaptureCamera& cam = cameras.at(static_cast<size_t>(view));
  if (cam.OnCaptureClock()) return capture_frame;
  // Capture frame g is at (g - 1) / fps; the camera's frame x at
  // offset_s + (1 + drift) (x - 1) / fps.
  const double time_s = (capture_frame - 1) / fps;
  return (time_s - cam.offset_s) / (1.0 + cam.drift_ppm * 1e-6) * fps + 1.0;
}

StatusOr<CaptureManifest> ParseCaptureManifest(const std::string& text, const std::string& source) {
  // NaN / Infinity tokens (not JSON, but Python writes them) are told from absent fields.
  ARCO_ASSIGN_OR_RETURN(Json j, ParseJsonMarkingNonFinite(text, source));
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
    return f.Bad("instrument",
                 "is \"" + m.instrument + "\"; must be cello, violin, viola, double_bass or none");
  }
  ARCO_RETURN_IF_ERROR(f.Number("fps", true, &m.fps));
  if (!(m.fps > 0 && m.fps <= kMaxCaptureFps)) {
    return f.Bad("fps",
                 "is " + Written(*f.Find("fps")) + "; must be in (0, 10000] frames per second");
  }
  const Json* frames = f.Find("frames");
  if (!frames || frames->is_null()) return f.Missing("frames");
  if (!frames->is_object()) return f.Bad("frames", "must be an object {\"first\", \"count\"}");
  Fields ff(*frames, source, "frames.");
  ARCO_RETURN_IF_ERROR(ff.Integer("first", true, &m.frame_first));
  ARCO_RETURN_IF_ERROR(ff.Integer("count", true, &m.frame_count));
  if (m.frame_count < 0 || m.frame_count > kMaxCaptureFrames) {
    return ff.Bad("count", "is " + std::to_string(m.frame_count) + "; must be in [0, 1e8]");
  }
  if (m.frame_first < 0 || m.frame_first > kMaxCaptureFrameNumber) {
    return ff.Bad("first",
                  "is " + std::to_string(m.frame_first) +
                      "; must be in [0, 2^40] (global frame "
                      "numbers, 1 for the recording's first frame)");
  }
  ARCO_RETURN_IF_ERROR(f.Number("tuning_a4_hz", false, &m.tuning_a4_hz));
  if (!kA4RangeHz.Contains(m.tuning_a4_hz)) {
    return f.Bad(
        "tuning_a4_hz",
        "is " + Written(*f.Find("tuning_a4_hz")) + "; must be in " + kA4RangeHz.ToString() + " Hz");
  }
  ARCO_RETURN_IF_ERROR(f.String("calibration", true, &m.calibration));
  if (m.calibration.empty()) return f.Bad("calibration", "is empty; must name a calibration file");
  if (const Json* audio = f.Find("audio"); audio && !audio->is_null()) {
    if (!audio->is_object()) return f.Bad("audio", "must be an object {\"file\", \"offset_s\"}");
    Fields fa(*audio, source, "audio.");
    ARCO_RETURN_IF_ERROR(fa.String("file", true, &m.audio));
    if (m.audio.empty()) return fa.Bad("file", "is empty; must name an audio file");
    ARCO_RETURN_IF_ERROR(fa.Number("offset_s", false, &m.audio_offset_s));
    ARCO_RETURN_IF_ERROR(fa.Number("sync_confidence", false, &m.audio_sync_confidence));
    if (!std::isnan(m.audio_sync_confidence) &&
        !(m.audio_sync_confidence >= 0 && m.audio_sync_confidence <= 1)) {
      return fa.Bad("sync_confidence", "must be in [0, 1]");
    }
  }
  if (const Json* k = f.Find("keypoints2d"); k && !k->is_null()) {
    if (!k->is_object()) return f.Bad("keypoints2d", "must be an object {\"file\", \"layout\"}");
    Fields fk(*k, source, "keypoints2d.");
    ARCO_RETURN_IF_ERROR(fk.String("file", true, &m.keypoints2d));
    if (m.keypoints2d.empty()) return fk.Bad("file", "is empty; must name a .npy file");
    ARCO_RETURN_IF_ERROR(fk.String("layout", true, &m.layout));
    if (const Json* names = fk.Find("names"); names && !names->is_null()) {
      if (!names->is_array()) return fk.Bad("names", "must be an array of strings");
      for (const Json& n : *names) {
        if (!n.is_string() || !NonFiniteToken(n).empty()) {
          return fk.Bad("names", "must be an array of strings");
        }
        m.keypoint_names.push_back(n.get<std::string>());
      }
    }
    const auto layout = m.Layout();
    if (!layout.ok()) return Status::Error(source + ": keypoints2d: " + layout.status().message());
    // An SPD layout holds one instrument family's points: a violin capture with the
    // cello's would run every stage and fail at the end naming a folder (issue 24).
    std::string family = m.layout;
    if (family.size() > 8 && family.compare(family.size() - 8, 8, "_contact") == 0)
      family.resize(family.size() - 8);
    if (family.rfind("spd_", 0) == 0 && m.instrument != "none") {
      const StatusOr<std::string> wanted = DetectionLayoutName(m.instrument);
      if (wanted.ok() && *wanted != family)
        return fk.Bad("layout",
                      "is \"" + m.layout + "\", but \"instrument\" is \"" + m.instrument +
                          "\", whose points are " + *wanted + " (correct one of them)");
    }
  }
  const Json* cams = f.Find("cameras");
  if (!cams || !cams->is_array() || cams->empty()) {
    return Status::Error(source + ": \"cameras\" must be a non-empty array");
  }
  const int64_t frame_last = m.frame_first + m.frame_count - 1;
  std::set<std::string> names;
  for (size_t i = 0; i < cams->size(); ++i) {
    CaptureCamera cam;
    const std::string prefix = "cameras[" + std::to_string(i) + "]";
    ARCO_RETURN_IF_ERROR(ParseCamera((*cams)[i], source, prefix, &cam));
    if (!names.insert(cam.name).second) {
      return Status::Error(source + ": camera \"" + cam.name + "\" is listed twice");
    }
    // Drops before frames.first still number the video's frames; after the last frame
    // or below 0 they name no frame of this recording.
    for (int64_t g : cam.dropped_frames) {
      if (g < 0 || g > frame_last) {
        return Status::Error(source + ": \"" + prefix + ".dropped_frames\" holds frame " +
                             std::to_string(g) + ", outside 0.." + std::to_string(frame_last) +
                             " (frames.first + frames.count - 1)");
      }
    }
    m.cameras.push_back(std::move(cam));
  }
  return m;
}

StatusOr<CaptureManifest> ReadCaptureManifest(const std::string& capture_dir) {
  const std::string path = CaptureManifestPath(capture_dir);
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
    if (c.rotate_deg != 0) cj["rotate_deg"] = c.rotate_deg;
    // Written only when set: a hardware-synced capture's manifest is unchanged.
    if (c.offset_s != 0) cj["offset_s"] = c.offset_s;
    if (c.drift_ppm != 0) cj["drift_ppm"] = c.drift_ppm;
    cj["dropped_frames"] = c.dropped_frames;
    j["cameras"].push_back(cj);
  }
  return j;
}

Status WriteCaptureManifest(const std::string& capture_dir, const CaptureManifest& manifest) {
  ARCO_RETURN_IF_ERROR(MakeDirectories(capture_dir));
  return WriteJsonFile(CaptureManifestPath(capture_dir), CaptureManifestToJson(manifest));
}

std::string CaptureManifestPath(const std::string& capture_dir) {
  return JoinPath(capture_dir, kCaptureManifestName);
}

std::string ResolveCapturePath(const std::string& dir, const std::string& entry) {
  if (entry.empty() || fs::path(entry).is_absolute()) return entry;
  return JoinPath(dir, entry);
}

StatusOr<std::string> DetectionLayoutName(const std::string& instrument) {
  if (instrument.empty() || instrument == "none") return std::string("coco_wholebody_133");
  ARCO_ASSIGN_OR_RETURN(const InstrumentKind kind, ParseInstrumentKind(instrument));
  return std::string(GetInstrumentInfo(kind).spd_layout);
}

Status CheckCaptureHasKeypoints2d(const std::string& capture_dir, const CaptureManifest& m) {
  if (!m.keypoints2d.empty()) return Status::Ok();
  return Status::Error(CaptureManifestPath(capture_dir) +
                       ": no 2D keypoints yet (no \"keypoints2d\" entry); run `arco detect " +
                       capture_dir + "` (or `arco capture import-keypoints`) first");
}

namespace {

std::string ShapeString(const std::vector<int64_t>& s) {
  std::string out = "(";
  for (size_t i = 0; i < s.size(); ++i) out += (i ? ", " : "") + std::to_string(s[i]);
  return out + ")";
}

}  // namespace

Status CheckKeypoints2dDtype(const std::string& source, const std::string& dtype, bool is_float) {
  // Pixel coordinates are fractional: an integer array is a writer's mistake (rounded
  // pixels, or scores of 0/1), not something to convert silently.
  if (is_float) return Status::Ok();
  return Status::Error(source + ": dtype " + dtype +
                       "; keypoints2d must be float32 or float64 (x_px, y_px, score; NaN = "
                       "missing)");
}

namespace {

// The header rules of CheckCaptureKeypoints2d (`path`: the file the header came from).
Status CheckKeypoints2dHeader(const std::string& capture_dir,
                              const CaptureManifest& m,
                              const std::string& path,
                              const NpyHeader& header) {
  const std::string manifest_path = CaptureManifestPath(capture_dir);
  ARCO_RETURN_IF_ERROR(CheckKeypoints2dDtype(path, header.dtype, header.is_float));
  StatusOr<KeypointLayout> layout = m.Layout();
  if (!layout.ok()) return layout.status().WithContext(manifest_path);
  const std::vector<int64_t> expected = {
      m.frame_count, static_cast<int64_t>(m.cameras.size()), layout->size(), 3};
  if (header.shape != expected) {
    return Status::Error(path + ": shape " + ShapeString(header.shape) +
                         " does not match capture.json " + ShapeString(expected) +
                         " (frames.count, cameras, " + layout->name + " points, 3)");
  }
  return Status::Ok();
}

// Dropped frames to NaN, then (kCaptureFrames) every camera at the capture's frame times.
StatusOr<NpyArray<double>> FinishKeypoints2d(const std::string& path,
                                             const CaptureManifest& m,
                                             KeypointTimes times,
                                             NpyArray<double> k) {
  ARCO_ASSIGN_OR_RETURN(KeypointLayout layout, m.Layout());
  if (k.shape.size() != 4) return Status::Error(path + ": changed while being read");
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
  if (times == KeypointTimes::kCaptureFrames) {
    for (size_t v = 0; v < m.cameras.size(); ++v)
      ResampleCameraKeypoints(m, static_cast<int>(v), &k);
  }
  return k;
}

}  // namespace

Status CheckCaptureKeypoints2d(const std::string& capture_dir, const CaptureManifest& m) {
  ARCO_RETURN_IF_ERROR(CheckCaptureHasKeypoints2d(capture_dir, m));
  const std::string path = ResolveCapturePath(capture_dir, m.keypoints2d);
  ARCO_ASSIGN_OR_RETURN(const NpyHeader header, ReadNpyHeader(path));
  return CheckKeypoints2dHeader(capture_dir, m, path, header);
}

StatusOr<NpyArray<double>> ReadCaptureKeypoints2d(const std::string& capture_dir,
                                                  const CaptureManifest& m,
                                                  KeypointTimes times) {
  ARCO_RETURN_IF_ERROR(CheckCaptureKeypoints2d(capture_dir, m));
  const std::string path = ResolveCapturePath(capture_dir, m.keypoints2d);
  ARCO_ASSIGN_OR_RETURN(NpyArray<double> k, ReadNpy<double>(path));
  return FinishKeypoints2d(path, m, times, std::move(k));
}

StatusOr<FileBytes> ReadCaptureKeypoints2dBytes(const std::string& capture_dir,
                                                const CaptureManifest& m) {
  ARCO_RETURN_IF_ERROR(CheckCaptureHasKeypoints2d(capture_dir, m));
  const std::string path = ResolveCapturePath(capture_dir, m.keypoints2d);
  // ReadNpyHeader's messages for a missing file and a folder.
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return Status::Error(path + ": file not found");
  if (std::filesystem::is_directory(path, ec)) {
    return Status::Error(path + ": is a directory, expected a file");
  }
  return FileBytes::Open(path);
}

StatusOr<NpyArray<double>> ParseCaptureKeypoints2d(std::string_view bytes,
                                                   const std::string& capture_dir,
                                                   const CaptureManifest& m,
                                                   KeypointTimes times) {
  ARCO_RETURN_IF_ERROR(CheckCaptureHasKeypoints2d(capture_dir, m));
  const std::string path = ResolveCapturePath(capture_dir, m.keypoints2d);
  ARCO_ASSIGN_OR_RETURN(const NpyHeader header, ParseNpyHeader(bytes, path));
  ARCO_RETURN_IF_ERROR(CheckKeypoints2dHeader(capture_dir, m, path, header));
  ARCO_ASSIGN_OR_RETURN(NpyArray<double> k, ParseNpy<double>(bytes, path));
  return FinishKeypoints2d(path, m, times, std::move(k));
}

void ResampleCameraKeypoints(const CaptureManifest& m, int view, NpyArray<double>* keypoints) {
  const CaptureCamera& cam = m.cameras.at(static_cast<size_t>(view));
  if (cam.OnCaptureClock()) return;
  NpyArray<double>& k = *keypoints;
  const int64_t frames = k.shape.at(0), points = k.shape.at(2);
  const int64_t v = view;
  // The camera's own rows, before they are overwritten.
  std::vector<double> own(static_cast<size_t>(frames * points * 3));
  for (int64_t f = 0; f < frames; ++f) {
    for (int64_t p = 0; p < points; ++p) {
      for (int c = 0; c < 3; ++c)
        own[static_cast<size_t>((f * points + p) * 3 + c)] = k.at(f, v, p, c);
    }
  }
  const auto at = [&](int64_t f, int64_t p, int c) {
    return own[static_cast<size_t>((f * points + p) * 3 + c)];
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int64_t f = 0; f < frames; ++f) {
    // Capture frame g at (g - 1) / fps is the camera's (fractional) global frame x.
    const double x = m.CameraFrameAt(view, static_cast<double>(m.frame_first + f));
    const double row = x - static_cast<double>(m.frame_first);
    double lower = std::floor(row);
    double w = row - lower;
    // Within a rounding error of a frame: that frame alone (no neighbour needed).
    if (w < 1e-9) w = 0;
    if (w > 1 - 1e-9) {
      lower += 1;
      w = 0;
    }
    const int64_t i0 = static_cast<int64_t>(lower);
    const int64_t i1 = w == 0 ? i0 : i0 + 1;
    const bool inside = lower >= 0 && i1 < frames;
    for (int64_t p = 0; p < points; ++p) {
      if (!inside) {
        for (int c = 0; c < 3; ++c) k.at(f, v, p, c) = nan;
        continue;
      }
      for (int c = 0; c < 2; ++c) k.at(f, v, p, c) = (1 - w) * at(i0, p, c) + w * at(i1, p, c);
      k.at(f, v, p, 2) = std::min(at(i0, p, 2), at(i1, p, 2));
      // std::min passes one NaN through only when it is the first argument.
      if (std::isnan(at(i0, p, 2)) || std::isnan(at(i1, p, 2))) k.at(f, v, p, 2) = nan;
    }
  }
}

}  // namespace arco
