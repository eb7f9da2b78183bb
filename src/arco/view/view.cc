#include "arco/view/view.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <set>

#include "arco/export/export.h"
#include "arco/export/overlay.h"
#include "arco/media/video_writer.h"
#include "arco/mocap/capture.h"
#include "arco/pipeline/result_folder.h"
#include "arco/refine/contacts_csv.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/synth/truth_folder.h"
#include "arco/util/check.h"
#include "arco/util/data_dir.h"
#include "arco/util/file_io.h"
#include "arco/util/json_io.h"
#include "arco/view/video_cache.h"

#ifndef ARCO_VIEW_WEB_DIR
#define ARCO_VIEW_WEB_DIR ""
#endif
#ifndef ARCO_VIEW_THREE_JS
#define ARCO_VIEW_THREE_JS ""
#endif

namespace arco::view {
namespace {

constexpr float kNaNf = std::numeric_limits<float>::quiet_NaN();
// The page's own files, copied from the web folder.
constexpr const char* kWebFiles[] = {"index.html", "viewer.js", "viewer.css"};
// Methods in the page's order; triangulation is shown only when no refined method exists.
constexpr const char* kMethods[] = {"arco", "paper", "vision", "triangulation"};

// Collects the arrays: each one a .bin file and, for data.js, its base64 text.
class ArrayWriter {
 public:
  ArrayWriter(std::string dir, bool embed) : dir_(std::move(dir)), embed_(embed) {}

  // {"file", "shape"} of the array written as `name`.bin.
  StatusOr<Json> Add(const std::string& name,
                     const std::vector<int64_t>& shape,
                     const std::vector<float>& values) {
    int64_t count = 1;
    for (int64_t s : shape) count *= s;
    ARCO_CHECK(count == static_cast<int64_t>(values.size()));
    std::string bytes(values.size() * sizeof(float), '\0');
    // The page reads Float32Array, which is the platform's order: little-endian on every
    // platform a browser runs on; the bytes are written little-endian explicitly.
    for (size_t i = 0; i < values.size(); ++i) {
      uint32_t u;
      std::memcpy(&u, &values[i], 4);
      for (int b = 0; b < 4; ++b) bytes[4 * i + b] = static_cast<char>((u >> (8 * b)) & 0xff);
    }
    const std::string file = name + ".bin";
    ARCO_RETURN_IF_ERROR(AtomicWriteFile(JoinPath(dir_, file), bytes));
    if (embed_) embedded_[file] = Base64(bytes);
    bytes_ += static_cast<int64_t>(bytes.size());
    return Json{{"file", file}, {"shape", shape}};
  }
  const Json& embedded() const { return embedded_; }
  int64_t bytes() const { return bytes_; }

 private:
  std::string dir_;
  bool embed_;
  Json embedded_ = Json::object();
  int64_t bytes_ = 0;
};

std::vector<float> ToFloat(const std::vector<double>& v) {
  return std::vector<float>(v.begin(), v.end());
}

// Median of the finite values; NaN when none.
float FiniteMedian(std::vector<double>& v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return kNaNf;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return static_cast<float>(n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]));
}

int StateCode(const std::string& state) {
  if (state == "open" || state == "open_string") return 1;
  if (state == "pressed") return 2;
  if (state == "uncertain") return 3;
  return 0;  // rest, ""
}

std::string Extension(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  return path.substr(dot);
}

// The capture's audio file and offset, read through the capture folder's owner.
struct AudioSource {
  std::string path;
  double offset_s = 0;
};
StatusOr<AudioSource> FindAudio(const pipeline::ResultHeader& header) {
  if (header.capture_dir.empty()) {
    return Status::Error("result.json names no capture (its audio is not found)");
  }
  ARCO_ASSIGN_OR_RETURN(const CaptureManifest capture, ReadCaptureManifest(header.capture_dir));
  if (capture.audio.empty()) {
    return Status::Error(JoinPath(header.capture_dir, "capture.json") + ": no audio file");
  }
  AudioSource out;
  out.path = ResolveCapturePath(header.capture_dir, capture.audio);
  out.offset_s = capture.audio_offset_s;
  if (!FileExists(out.path)) return Status::Error(out.path + ": audio file not found");
  return out;
}

// Per-frame errors of a method against a synthetic truth (CAPTURE/truth/, synth/): the
// mean distance of the left hand's 21 points, and the distance between the pressed
// contacts when both press (mm; NaN where not defined). Points are matched by name.
struct FrameErrors {
  std::vector<float> left_hand_mm, contact_mm;
};
FrameErrors ErrorsAgainstTruth(const exporter::ExportData& data,
                               const std::vector<refine::ContactRow>& contacts,
                               const synth::TruthFolder& truth,
                               const KeypointLayout& truth_layout) {
  const int64_t f = data.frames();
  FrameErrors out{std::vector<float>(f, kNaNf), std::vector<float>(f, kNaNf)};
  std::vector<std::pair<int, int>> hand;  // (method column, truth column)
  for (int p = 0; p < data.points(); ++p) {
    const std::string& name = data.keypoint_names[p];
    const int t = truth_layout.Find(name);
    if (name.rfind("left_hand_", 0) == 0 && t >= 0) hand.emplace_back(p, t);
  }
  for (int64_t i = 0; i < f; ++i) {
    double sum = 0;
    int n = 0;
    for (const auto& [p, t] : hand) {
      const Eigen::Vector3d d = data.At(i, p) - pipeline::PointAt(truth.points3d, i, t);
      if (d.allFinite()) sum += d.norm(), ++n;
    }
    if (n > 0) out.left_hand_mm[i] = static_cast<float>(sum / n);
  }
  for (const auto& r : contacts) {
    if (r.frame < 0 || r.frame >= f || r.frame >= static_cast<int64_t>(truth.contacts.size())) {
      continue;
    }
    const auto& t = truth.contacts[r.frame];
    if (r.state != "pressed" || t.state != "pressed") continue;
    const double d = (r.point_mm - t.point_mm).norm();
    if (std::isfinite(d)) out.contact_mm[r.frame] = static_cast<float>(d);
  }
  return out;
}

// The regular files of `dir` (not hidden: no temporaries), sorted; with `recursive`, those
// of its subfolders too, as paths relative to `dir`.
std::vector<std::string> FilesOf(const std::string& dir, bool recursive) {
  namespace fs = std::filesystem;
  std::vector<std::string> out;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return out;
  if (recursive) {
    for (const auto& e : fs::recursive_directory_iterator(dir, ec)) {
      const std::string rel = fs::relative(e.path(), dir, ec).string();
      if (e.is_regular_file() && e.path().filename().string()[0] != '.') out.push_back(rel);
    }
  } else {
    for (const auto& e : fs::directory_iterator(dir, ec)) {
      const std::string name = e.path().filename().string();
      if (e.is_regular_file() && name[0] != '.') out.push_back(name);
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The cache key of camera `v`'s video (docs/view.md, "Video cache"): what the overlay
// reads and draws, and how it is encoded. The result's files in full: its top-level files
// (result.json: frames, units, stages; pitch.csv, notes.csv) and every file of the
// drawn method's, the instrument's and the triangulation's folders (a superset of what
// exporter::LoadExportData and WriteOverlay read: a change anywhere there encodes again).
// The capture's capture.json (cameras, rotations, video paths) and calibration in full;
// its video by size and ends (HashVideoSource): not its path or mtime, so a capture moved
// or copied keeps its cache.
StatusOr<std::string> VideoKey(const ViewOptions& options,
                               const pipeline::ResultHeader& header,
                               const CaptureManifest& capture,
                               int v,
                               const std::string& method) {
  Sha256 hash;
  hash.AddField("arco-view-video", std::to_string(kVideoCacheVersion));
  hash.AddField("libavcodec", std::to_string(media::CodecLibraryVersion()));
  hash.AddField("codec", "webm-vp8");
  hash.AddField("method", method);
  hash.AddField("camera", std::to_string(v) + "/" + capture.cameras[v].name);
  char scale[40];
  std::snprintf(scale, sizeof(scale), "%.17g", options.video_scale);
  hash.AddField("scale", scale);
  for (const std::string& sub : {std::string(),
                                 std::string(pipeline::kTriangulationStage),
                                 std::string(pipeline::kInstrumentStage),
                                 method}) {
    const std::string dir = sub.empty() ? options.result_dir : JoinPath(options.result_dir, sub);
    for (const auto& file : FilesOf(dir, !sub.empty())) {
      ARCO_RETURN_IF_ERROR(
          HashWholeFile(hash, "result/" + JoinPath(sub, file), JoinPath(dir, file)));
    }
  }
  ARCO_RETURN_IF_ERROR(
      HashWholeFile(hash, "capture.json", CaptureManifestPath(header.capture_dir)));
  ARCO_RETURN_IF_ERROR(HashWholeFile(
      hash, "calibration", ResolveCapturePath(header.capture_dir, capture.calibration)));
  const std::string& video = capture.cameras[v].video;
  hash.AddField("has_video", video.empty() ? "0" : "1");
  if (!video.empty()) {
    ARCO_RETURN_IF_ERROR(
        HashVideoSource(hash, "video", ResolveCapturePath(header.capture_dir, video)));
  }
  return hash.HexDigest();
}

Json SidecarOf(const ViewVideo& video, int64_t bytes) {
  return {{"format", "arco-view-video-cache"},
          {"bytes", bytes},
          {"camera", video.camera},
          {"source", video.source},
          {"method", video.method},
          {"width", video.width},
          {"height", video.height},
          {"frames", video.frames}};
}

// The cached video of `key` copied to `dest`, or nullopt when there is no whole entry: no
// sidecar, one that does not parse, or a video whose size is not the sidecar's.
std::optional<ViewVideo> TakeCached(const std::string& cache_dir,
                                    const std::string& key,
                                    const std::string& dest) {
  namespace fs = std::filesystem;
  const VideoCacheEntry entry = CacheEntryPaths(cache_dir, key);
  std::error_code ec;
  if (!fs::exists(entry.sidecar, ec)) return std::nullopt;
  auto side = ReadJsonFile(entry.sidecar);
  const auto size = fs::file_size(entry.video, ec);
  if (!side.ok() || ec || !side->is_object() || !side->contains("bytes") ||
      side->value("bytes", int64_t{-1}) != static_cast<int64_t>(size)) {
    return std::nullopt;
  }
  ViewVideo video;
  try {
    video.camera = side->at("camera").get<std::string>();
    video.source = side->at("source").get<std::string>();
    video.method = side->at("method").get<std::string>();
    video.width = side->at("width").get<int>();
    video.height = side->at("height").get<int>();
    video.frames = side->at("frames").get<int64_t>();
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (!fs::copy_file(entry.video, dest, fs::copy_options::overwrite_existing, ec) || ec) {
    return std::nullopt;
  }
  // Least recently used: the entry's mtime is its last use.
  const auto now = fs::file_time_type::clock::now();
  fs::last_write_time(entry.video, now, ec);
  fs::last_write_time(entry.sidecar, now, ec);
  video.cached = true;
  video.cache_key = key;
  return video;
}

// Encodes camera `overlay.camera`'s video into the cache (a hidden temporary renamed to
// the entry, then the sidecar) and copies it to `dest`.
StatusOr<ViewVideo> EncodeIntoCache(const exporter::OverlayOptions& overlay,
                                    const std::string& cache_dir,
                                    const std::string& key,
                                    const std::string& dest) {
  namespace fs = std::filesystem;
  const VideoCacheEntry entry = CacheEntryPaths(cache_dir, key);
  // Hidden (never taken as an entry) and this process's own: two viewers encoding the
  // same key each write their temporary and the last rename wins, with the same bytes.
  const std::string tmp = JoinPath(cache_dir, "." + key + "-" + std::to_string(getpid()) + ".webm");
  auto written = exporter::WriteOverlay(overlay, tmp, entry.video);
  std::error_code ec;
  if (!written.ok()) {
    fs::remove(tmp, ec);
    return written.status();
  }
  ViewVideo video;
  video.camera = written->camera;
  video.source = written->video;
  video.method = overlay.method;
  video.width = written->width;
  video.height = written->height;
  video.frames = written->frames;
  video.cache_key = key;
  const auto bytes = fs::file_size(tmp, ec);
  if (!ec) fs::rename(tmp, entry.video, ec);
  if (ec) {
    fs::remove(tmp, ec);
    return Status::Error(entry.video + ": cannot write to the video cache (--no-cache skips it)");
  }
  ARCO_RETURN_IF_ERROR(
      AtomicWriteFile(entry.sidecar, SidecarOf(video, static_cast<int64_t>(bytes)).dump(1) + "\n"));
  if (!fs::copy_file(entry.video, dest, fs::copy_options::overwrite_existing, ec) || ec) {
    return Status::Error(dest + ": cannot copy the cached video");
  }
  return video;
}

// The camera videos with the overlay of `method` (exporter::WriteOverlay), as WebM VP8,
// taken from the cache when it has them (options.cache_dir).
// The cameras: the options' (each must be one of the capture's), else the first camera
// with a video; none when the capture has no video (not an error).
StatusOr<std::vector<ViewVideo>> WriteVideos(const ViewOptions& options,
                                             const pipeline::ResultHeader& header,
                                             const std::string& method,
                                             const std::string& dir,
                                             int* evicted) {
  std::vector<ViewVideo> out;
  if (!options.videos || header.capture_dir.empty()) return out;
  auto read = ReadCaptureManifest(header.capture_dir);
  if (!read.ok()) {
    if (options.video_cameras.empty()) return out;  // no capture: no videos to show
    return read.status();
  }
  const CaptureManifest& capture = *read;
  std::vector<int> views;
  for (const auto& id : options.video_cameras) {
    const int v = capture.FindCamera(id);
    if (v < 0) {
      std::string names;
      for (const auto& c : capture.cameras) names += (names.empty() ? "" : ", ") + c.name;
      return Status::Error(CaptureManifestPath(header.capture_dir) + ": no camera '" + id +
                           "' (cameras: " + names + ")");
    }
    if (std::find(views.begin(), views.end(), v) == views.end()) views.push_back(v);
  }
  if (options.video_cameras.empty()) {
    for (size_t v = 0; v < capture.cameras.size(); ++v) {
      if (!capture.cameras[v].video.empty()) {
        views.push_back(static_cast<int>(v));
        break;
      }
    }
  }
  const bool cache = !options.cache_dir.empty() && !views.empty();
  if (cache) {
    const Status made = MakeDirectories(options.cache_dir);
    if (!made.ok()) {
      return Status::Error(options.cache_dir +
                           ": cannot create the video cache (--no-cache skips it)");
    }
  }
  std::set<std::string> used;
  for (const int v : views) {
    exporter::OverlayOptions overlay;
    overlay.result_dir = options.result_dir;
    overlay.camera = capture.cameras[v].name;
    overlay.method = method;
    overlay.scale = options.video_scale;
    const std::string file = "video_" + std::to_string(v) + ".webm";
    const std::string path = JoinPath(dir, file);
    const auto start = std::chrono::steady_clock::now();
    ViewVideo video;
    // An input the key cannot read (a missing calibration or video): encoded uncached,
    // so that the overlay itself reports what is wrong with the capture.
    const StatusOr<std::string> keyed =
        cache ? VideoKey(options, header, capture, v, method) : StatusOr<std::string>("");
    if (cache && keyed.ok()) {
      const std::string& key = *keyed;
      used.insert(key);
      std::optional<ViewVideo> hit = TakeCached(options.cache_dir, key, path);
      if (hit.has_value()) {
        video = *hit;
        // The capture may have moved since: name the video where it is now.
        if (!capture.cameras[v].video.empty()) {
          video.source = ResolveCapturePath(header.capture_dir, capture.cameras[v].video);
        }
      } else {
        ARCO_ASSIGN_OR_RETURN(video, EncodeIntoCache(overlay, options.cache_dir, key, path));
      }
    } else {
      ARCO_ASSIGN_OR_RETURN(const exporter::OverlaySummary written,
                            exporter::WriteOverlay(overlay, path, path));
      video.camera = written.camera;
      video.source = written.video;
      video.method = method;
      video.width = written.width;
      video.height = written.height;
      video.frames = written.frames;
    }
    video.file = file;
    video.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    out.push_back(video);
  }
  if (cache) {
    ARCO_ASSIGN_OR_RETURN(
        *evicted,
        EvictVideoCache(options.cache_dir, static_cast<int64_t>(options.cache_max_gb * 1e9), used));
  }
  return out;
}

}  // namespace

Status ViewOptions::Validate() const {
  if (result_dir.empty()) return Status::Error("result_dir is empty");
  ARCO_RETURN_IF_ERROR(CheckInRange("video_scale", video_scale, kViewVideoScaleRange));
  ARCO_RETURN_IF_ERROR(CheckInRange("cache_max_gb", cache_max_gb, kViewCacheMaxGbRange));
  if (!videos && !video_cameras.empty()) {
    return Status::Error("video cameras are named but videos are off");
  }
  for (const auto& c : video_cameras) {
    if (c.empty()) return Status::Error("a video camera's name is empty");
  }
  return Status::Ok();
}

std::string Base64(const std::string& bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v =
        (uint8_t(bytes[i]) << 16) | (uint8_t(bytes[i + 1]) << 8) | uint8_t(bytes[i + 2]);
    for (int k = 3; k >= 0; --k) out += kAlphabet[(v >> (6 * k)) & 63];
  }
  const size_t rest = bytes.size() - i;
  if (rest > 0) {
    uint32_t v = uint8_t(bytes[i]) << 16;
    if (rest == 2) v |= uint8_t(bytes[i + 1]) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += rest == 2 ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::vector<MissingStage> MissingStages(const std::string& result_dir) {
  static const MissingStage kStages[] = {
      {"triangulation", "arco triangulate (or arco run) writes it"},
      {"instrument", "arco run's instrument stage writes it: no strings, no fingerboard"},
      {"hand", "arco run's hand stage writes it"},
      {"pitch", "arco run's pitch stage writes it: no pitch curve, no notes"},
      {"vision", "arco refine writes it"},
      {"paper", "arco refine writes it"},
      {"arco", "arco refine writes it"}};
  const pipeline::ResultFolder folder(result_dir);
  std::vector<MissingStage> out;
  for (const auto& s : kStages) {
    auto has = folder.HasStage(s.stage);
    if (!has.ok() || !*has) out.push_back(s);
  }
  return out;
}

StatusOr<ViewSummary> WriteViewFolder(const ViewOptions& options, const std::string& dir) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  const pipeline::ResultFolder folder(options.result_dir);
  if (!FileExists(folder.ManifestPath())) {
    return Status::Error(folder.ManifestPath() + ": not found (not an arco result folder)");
  }
  ARCO_ASSIGN_OR_RETURN(const pipeline::ResultHeader header, folder.ReadHeader());
  ARCO_ASSIGN_OR_RETURN(const Json result, folder.ReadManifest());
  // The page's own files: an installed arco's data folder, else the source tree's
  // (util/data_dir.h); checked before any work, naming the file that is missing.
  const std::string web_dir =
      options.web_dir.empty() ? DataPath("view/web", ARCO_VIEW_WEB_DIR) : options.web_dir;
  const std::string three_js = options.three_js.empty()
                                   ? DataPath("view/three.min.js", ARCO_VIEW_THREE_JS)
                                   : options.three_js;
  for (const char* file : kWebFiles) {
    if (!FileExists(JoinPath(web_dir, file))) {
      return Status::Error(JoinPath(web_dir, file) + ": the viewer's page is missing (" +
                           DataDirHint() + ")");
    }
  }
  if (!FileExists(three_js)) {
    return Status::Error(three_js + ": three.js not found (" + DataDirHint() +
                         "; in a source tree scripts/fetch_view_tools installs it)");
  }

  ViewSummary summary;
  summary.missing = MissingStages(options.result_dir);
  ArrayWriter arrays(dir, options.embed_data);
  Json manifest = {{"format", "arco-view"},
                   {"version", 1},
                   {"name", result.value("name", "")},
                   {"instrument", result.value("instrument", "")},
                   {"fps", header.fps},
                   {"frame_first", header.frame_first}};

  // A synthetic capture's truth, when there is one whose frames match the result's.
  std::optional<synth::TruthFolder> truth;
  const KeypointLayout* truth_layout = nullptr;
  const std::string truth_dir =
      header.capture_dir.empty() ? "" : JoinPath(header.capture_dir, synth::kTruthFolderName);
  if (!truth_dir.empty() && FileExists(synth::TruthManifestPath(truth_dir))) {
    auto read = synth::ReadTruthFolder(truth_dir);
    if (read.ok()) {
      truth_layout = FindKeypointLayout(read->manifest.truth_layout);
      if (truth_layout != nullptr && read->manifest.frames == header.frame_count) {
        truth = std::move(*read);
      }
    }
  }
  manifest["truth"] = truth.has_value();

  // Every method's points through the export layer's reader.
  Json methods = Json::array();
  std::vector<exporter::ExportData> loaded;
  ARCO_ASSIGN_OR_RETURN(const auto stages, folder.PointStages());
  for (const char* method : kMethods) {
    const bool present =
        std::any_of(stages.begin(), stages.end(), [&](const auto& s) { return s.name == method; });
    if (!present) continue;
    if (std::string(method) == "triangulation" && !loaded.empty()) continue;
    exporter::ExportOptions eo;
    eo.result_dir = options.result_dir;
    eo.method = method;
    ARCO_ASSIGN_OR_RETURN(exporter::ExportData data, exporter::LoadExportData(eo));
    Json m = {{"name", method}, {"keypoint_names", data.keypoint_names}};
    ARCO_ASSIGN_OR_RETURN(
        m["points"],
        arrays.Add("points_" + data.method, data.points_mm.shape, ToFloat(data.points_mm.data)));
    // Contacts of the refined methods (contacts.csv, refine/contacts_csv.h).
    const std::string contacts_path = folder.ContactsPath(method);
    std::vector<refine::ContactRow> rows;
    if (FileExists(contacts_path)) {
      ARCO_ASSIGN_OR_RETURN(rows, refine::ReadContactsCsv(contacts_path));
      const int64_t f = data.frames();
      std::vector<float> state(f, 0), string(f, 0), finger(f, 0), from_nut(f, kNaNf),
          point(f * 3, kNaNf);
      for (const auto& r : rows) {
        if (r.frame < 0 || r.frame >= f) continue;
        state[r.frame] = StateCode(r.state);
        string[r.frame] = r.state == "open" ? r.open_string : r.string;
        finger[r.frame] = r.finger;
        from_nut[r.frame] = r.from_nut_mm;
        for (int k = 0; k < 3; ++k) point[3 * r.frame + k] = r.point_mm[k];
      }
      Json c;
      const std::string p = "contact_" + data.method + "_";
      ARCO_ASSIGN_OR_RETURN(c["state"], arrays.Add(p + "state", {f}, state));
      ARCO_ASSIGN_OR_RETURN(c["string"], arrays.Add(p + "string", {f}, string));
      ARCO_ASSIGN_OR_RETURN(c["finger"], arrays.Add(p + "finger", {f}, finger));
      ARCO_ASSIGN_OR_RETURN(c["from_nut_mm"], arrays.Add(p + "from_nut_mm", {f}, from_nut));
      ARCO_ASSIGN_OR_RETURN(c["point_mm"], arrays.Add(p + "point_mm", {f, 3}, point));
      m["contacts"] = c;
    }
    if (truth.has_value() && data.frames() == truth->points3d.shape[0]) {
      const FrameErrors e = ErrorsAgainstTruth(data, rows, *truth, *truth_layout);
      Json ej;
      const int64_t f = data.frames();
      const std::string p = "error_" + data.method + "_";
      ARCO_ASSIGN_OR_RETURN(ej["left_hand_mm"],
                            arrays.Add(p + "left_hand_mm", {f}, e.left_hand_mm));
      ARCO_ASSIGN_OR_RETURN(ej["contact_mm"], arrays.Add(p + "contact_mm", {f}, e.contact_mm));
      m["errors"] = ej;
    }
    methods.push_back(m);
    summary.methods.push_back(method);
    loaded.push_back(std::move(data));
  }
  if (loaded.empty()) {
    return Status::Error(
        folder.ManifestPath() +
        ": the result has no 3D points to show (run arco triangulate or arco run)");
  }
  manifest["methods"] = methods;
  const exporter::ExportData& first = loaded.front();
  summary.frames = first.frames();
  summary.keypoints = first.points();
  manifest["frames"] = first.frames();

  manifest["strings"] = nullptr;
  if (!first.strings_mm.shape.empty()) {
    ARCO_ASSIGN_OR_RETURN(
        manifest["strings"],
        arrays.Add("strings", first.strings_mm.shape, ToFloat(first.strings_mm.data)));
  }
  // Per-frame quality: the median over the triangulated points of their RMS reprojection
  // error and of their inlier views.
  manifest["quality"] = nullptr;
  if (!first.reprojection_px.shape.empty()) {
    const int64_t f = first.frames();
    std::vector<float> rms(f), views(f);
    for (int64_t i = 0; i < f; ++i) {
      std::vector<double> r, v;
      for (int p = 0; p < first.points(); ++p) {
        if (first.views.at(i, p) <= 0) continue;
        r.push_back(first.reprojection_px.at(i, p));
        v.push_back(first.views.at(i, p));
      }
      rms[i] = FiniteMedian(r);
      views[i] = FiniteMedian(v);
    }
    Json q;
    ARCO_ASSIGN_OR_RETURN(q["reprojection_px"], arrays.Add("quality_reprojection_px", {f}, rms));
    ARCO_ASSIGN_OR_RETURN(q["views"], arrays.Add("quality_views", {f}, views));
    manifest["quality"] = q;
  }

  // Pitch (one row per video frame) and notes.
  manifest["pitch"] = nullptr;
  manifest["notes"] = Json::array();
  ARCO_ASSIGN_OR_RETURN(const bool has_pitch, folder.HasStage(pipeline::kPitchStage));
  if (has_pitch) {
    ARCO_ASSIGN_OR_RETURN(const auto pitch, folder.ReadPitch());
    const int64_t f = first.frames();
    std::vector<float> f0(f, 0), confidence(f, 0);
    for (const auto& p : pitch) {
      if (p.frame < 0 || p.frame >= f) continue;
      f0[p.frame] = p.voiced ? static_cast<float>(p.f0_hz) : 0.f;
      confidence[p.frame] = static_cast<float>(p.confidence);
    }
    Json pj = {{"a4_hz", result["stages"]["pitch"].value("a4_hz", 440.0)}};
    ARCO_ASSIGN_OR_RETURN(pj["f0_hz"], arrays.Add("pitch_f0_hz", {f}, f0));
    ARCO_ASSIGN_OR_RETURN(pj["confidence"], arrays.Add("pitch_confidence", {f}, confidence));
    manifest["pitch"] = pj;
    // notes.csv's reader returns times and median pitch only: the note and its cents are
    // derived here as notes.csv derives them, s = 69 + 12 log2(f0 / a4) (audio/notes.h).
    ARCO_ASSIGN_OR_RETURN(const auto notes, folder.ReadNotes());
    const double a4_hz = pj["a4_hz"].get<double>();
    for (const auto& n : notes) {
      const double semitones = 69.0 + 12.0 * std::log2(n.median_f0_hz / a4_hz);
      const int midi = static_cast<int>(std::lround(semitones));
      manifest["notes"].push_back({{"onset_s", n.onset_s},
                                   {"offset_s", n.offset_s},
                                   {"median_f0_hz", n.median_f0_hz},
                                   {"midi_note", midi},
                                   {"cents", 100.0 * (semitones - midi)}});
    }
  }

  // The capture's audio, copied.
  manifest["audio"] = nullptr;
  auto audio = FindAudio(header);
  if (audio.ok()) {
    ARCO_ASSIGN_OR_RETURN(const std::string bytes, ReadFileToString(audio->path));
    const std::string name = "audio" + Extension(audio->path);
    ARCO_RETURN_IF_ERROR(AtomicWriteFile(JoinPath(dir, name), bytes));
    manifest["audio"] = {{"file", name}, {"offset_s", audio->offset_s}};
    summary.audio = audio->path;
  } else {
    summary.missing.push_back({"audio", audio.status().message()});
  }
  // The camera videos, with the overlay of the first method that has one.
  manifest["videos"] = Json::array();
  std::string overlay_method;
  for (const auto& m : summary.methods) {
    const auto& names = exporter::ExportMethodNames();
    if (overlay_method.empty() && std::find(names.begin(), names.end(), m) != names.end()) {
      overlay_method = m;
    }
  }
  if (!overlay_method.empty()) {
    ARCO_ASSIGN_OR_RETURN(
        summary.videos, WriteVideos(options, header, overlay_method, dir, &summary.cache_evicted));
    for (const auto& v : summary.videos)
      ++(v.cached ? summary.videos_cached : summary.videos_encoded);
  } else if (!options.video_cameras.empty()) {
    return Status::Error(folder.ManifestPath() +
                         ": no refined method (arco, paper, vision) to draw over the videos");
  }
  for (const auto& v : summary.videos) {
    manifest["videos"].push_back({{"camera", v.camera},
                                  {"file", v.file},
                                  {"method", v.method},
                                  {"width", v.width},
                                  {"height", v.height},
                                  {"frames", v.frames}});
  }
  Json missing = Json::array();
  for (const auto& m : summary.missing) missing.push_back({{"stage", m.stage}, {"why", m.why}});
  manifest["missing"] = missing;

  // The page.
  for (const char* file : kWebFiles) {
    auto text = ReadFileToString(JoinPath(web_dir, file));
    if (!text.ok())
      return Status::Error(JoinPath(web_dir, file) + ": the viewer's page is missing");
    ARCO_RETURN_IF_ERROR(AtomicWriteFile(JoinPath(dir, file), *text));
  }
  auto three = ReadFileToString(three_js);
  if (!three.ok()) {
    return Status::Error(three_js + ": three.js not found (scripts/fetch_view_tools installs it)");
  }
  ARCO_RETURN_IF_ERROR(AtomicWriteFile(JoinPath(dir, "three.min.js"), *three));
  ARCO_RETURN_IF_ERROR(AtomicWriteFile(JoinPath(dir, "manifest.json"), manifest.dump(1) + "\n"));
  // data.js always exists (index.html loads it): null when the page fetches the arrays.
  const Json data = options.embed_data ? Json{{"manifest", manifest}, {"arrays", arrays.embedded()}}
                                       : Json(nullptr);
  ARCO_RETURN_IF_ERROR(
      AtomicWriteFile(JoinPath(dir, "data.js"), "window.ARCO_VIEW_DATA = " + data.dump() + ";\n"));
  summary.bytes = arrays.bytes();
  return summary;
}

}  // namespace arco::view
