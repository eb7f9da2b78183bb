// `arco view`: a result folder as a self-contained web page (docs/view.md): the 3D of every
// method with the take's audio, pitch, contacts and per-frame quality. Results are read
// through the export layer's reader (exporter::LoadExportData) and pipeline::ResultFolder,
// never a second reader.
//
// The page folder: index.html, viewer.js and viewer.css (src/arco/view/web/), three.min.js
// (npm `three`, fetched by scripts/fetch_view_tools), the capture's audio file, and the data:
// manifest.json (shapes, names, fps, methods, notes, what is missing) and one
// little-endian float32 .bin per array, row-major as the .npy it comes from. A page opened
// from disk (file://) cannot fetch(), so with `embed_data` the same manifest and arrays
// are also written as data.js (the arrays base64-encoded), which the page reads first.
//
// Time: frame k of the arrays (from 0) is shown at k / fps of the video; the audio time of
// frame k is audio_offset_s + k / fps (mocap/capture.h).
//
// Videos: the capture's camera videos, each written with the overlay of the page's first
// method (exporter::WriteOverlay: skeleton, strings, contact, finger numbers, note) as
// video_<camera index>.webm (VP8, which every browser plays), one frame per result frame
// at the capture's fps, so frame k of the page is the video's k / fps too. Each is taken
// from the cache (video_cache.h) when its inputs are those of an earlier encode.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "arco/util/number_range.h"
#include "arco/util/status.h"

namespace arco::view {

inline constexpr NumberRange kViewVideoScaleRange = Closed(0.05, 1);
inline constexpr NumberRange kViewCacheMaxGbRange = Closed(0, 1e6);

struct ViewOptions {
  std::string result_dir;   // an `arco run` result folder (result.json)
  bool embed_data = false;  // also write data.js, for pages opened from disk
  // Where the page's own files and three.min.js are; "" = the data folder's view/web and
  // view/three.min.js (util/data_dir.h), else, for a build-tree arco, the source tree's
  // paths compiled in (ARCO_VIEW_WEB_DIR, ARCO_VIEW_THREE_JS).
  std::string web_dir;
  std::string three_js;
  // The camera videos with the overlay: the cameras (names or serials; empty: the first
  // camera of capture.json that has a video, none when no camera has one), and their size
  // as a fraction of the calibration's image.
  bool videos = true;
  std::vector<std::string> video_cameras;
  double video_scale = 0.5;
  // The cache of encoded videos (view/video_cache.h, docs/view.md "Video cache"): "" = no
  // cache (every video encoded); the CLI's default is DefaultVideoCacheDir(). Entries
  // beyond cache_max_gb (10^9 bytes) are removed, least recently used first.
  std::string cache_dir;
  double cache_max_gb = 5;
  Status Validate() const;
};

// A camera video written into the page.
struct ViewVideo {
  std::string camera;  // the capture camera's name
  std::string file;    // in the page's folder
  std::string source;  // the capture's video ("": none, the overlay on black)
  std::string method;  // whose overlay is drawn
  int width = 0, height = 0;
  int64_t frames = 0;
  double seconds = 0;     // the time it took to write
  bool cached = false;    // copied from the cache (not encoded)
  std::string cache_key;  // the SHA-256 key ("" : no cache)
};

// A stage the page cannot show, and what writes it.
struct MissingStage {
  std::string stage;
  std::string why;
};

struct ViewSummary {
  std::vector<std::string> methods;  // shown, in the page's order (arco, paper, vision)
  std::vector<MissingStage> missing;
  int64_t frames = 0;
  int keypoints = 0;
  std::string audio;  // the audio file copied ("" when none)
  int64_t bytes = 0;  // of the data arrays
  std::vector<ViewVideo> videos;
  int videos_encoded = 0, videos_cached = 0;
  int cache_evicted = 0;  // entries removed to keep the cache within cache_max_gb
};

// The stages a complete result has and the command that writes each (the page and the
// terminal both list those missing).
std::vector<MissingStage> MissingStages(const std::string& result_dir);

// Writes the page folder into `dir` (an existing empty folder: a caller wanting an atomic
// output passes an OutputSet temporary). Errors: no result.json, a result with no
// method points at all, a page file or three.min.js not found, a video camera the
// capture does not have (or a video that cannot be read).
StatusOr<ViewSummary> WriteViewFolder(const ViewOptions& options, const std::string& dir);

// RFC 4648 base64 (with padding), for data.js.
std::string Base64(const std::string& bytes);

}  // namespace arco::view
