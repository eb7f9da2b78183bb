// The cache of `arco view`'s encoded camera videos (docs/view.md, "Video cache"): encoding
// one camera's overlay video takes about 1.2 s per second of take, so a second start of
// the viewer with the same inputs copies the WebM encoded the first time.
//
// An entry is CACHE_DIR/KEY.webm with its sidecar CACHE_DIR/KEY.json (the byte count and
// what the page lists of the video). KEY is the SHA-256 (FIPS 180-4, libavutil's) of
// everything that determines the video's bytes (VideoCacheKey). The video is encoded into
// a hidden temporary of the cache folder and renamed, then the sidecar is written
// atomically: an interrupted encode leaves no entry, and an entry whose size is not the
// sidecar's (a truncated or overwritten file) is encoded again. The folder is bounded:
// after each start, entries beyond max_bytes are removed, least recently used first (an
// entry's mtime is set when it is used).
#pragma once

#include <cstdint>
#include <set>
#include <string>
#include <string_view>

#include "arco/util/status.h"

struct AVSHA;

namespace arco::view {

// Bumped whenever the overlay's drawing or the viewer's encoding changes the bytes of a
// video for the same inputs (export/overlay.cc, media/video_writer.cc): older entries
// are then never matched and age out.
inline constexpr int kVideoCacheVersion = 1;

// $XDG_CACHE_HOME/arco/view, else $HOME/.cache/arco/view (XDG Base Directory
// Specification); "" when neither variable is set.
std::string DefaultVideoCacheDir();

// SHA-256 through libavutil (av_sha), a dependency of the media layer already.
class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;
  void Add(std::string_view bytes);
  // A labelled field: "label", its length and its bytes, so that no two different
  // sequences of fields hash the same bytes.
  void AddField(std::string_view label, std::string_view value);
  std::string HexDigest();  // 64 lowercase hex digits; ends the hash

 private:
  AVSHA* ctx_;
};

// Adds a file's whole content (and its size) under `label`. Error: the file cannot be read.
Status HashWholeFile(Sha256& hash, const std::string& label, const std::string& path);

// Adds a video source cheaply: its size and its first and last `sample_bytes` (a capture
// video is hundreds of MB; any re-encode or edit changes its size or its container's
// header and index, which lie in those ends). An image folder: each file's name, size and
// ends of 4 KiB. Error: the path cannot be read.
Status HashVideoSource(Sha256& hash,
                       const std::string& label,
                       const std::string& path,
                       int64_t sample_bytes = 1 << 20);

// A cache entry: its video and sidecar paths.
struct VideoCacheEntry {
  std::string video, sidecar;
};
VideoCacheEntry CacheEntryPaths(const std::string& cache_dir, const std::string& key);

// Removes entries (video, sidecar) beyond `max_bytes` in all, oldest mtime first (ties by
// name), never those in `keep`; also temporaries of interrupted encodes older than a day.
// Returns the number of entries removed.
StatusOr<int> EvictVideoCache(const std::string& cache_dir,
                              int64_t max_bytes,
                              const std::set<std::string>& keep);

}  // namespace arco::view
