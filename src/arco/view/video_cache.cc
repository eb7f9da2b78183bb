#include "arco/view/video_cache.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <vector>

#include "arco/util/check.h"
#include "arco/util/file_io.h"

extern "C" {
#include <libavutil/mem.h>
#include <libavutil/sha.h>
}

namespace arco::view {
namespace fs = std::filesystem;

std::string DefaultVideoCacheDir() {
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  // The specification: a relative path in XDG_CACHE_HOME is invalid and ignored.
  if (xdg != nullptr && xdg[0] == '/') return JoinPath(JoinPath(xdg, "arco"), "view");
  const char* home = std::getenv("HOME");
  if (home != nullptr && home[0] != '\0') return JoinPath(home, ".cache/arco/view");
  return "";
}

Sha256::Sha256() : ctx_(av_sha_alloc()) {
  ARCO_CHECK(ctx_ != nullptr);
  ARCO_CHECK(av_sha_init(ctx_, 256) == 0);
}

Sha256::~Sha256() { av_free(ctx_); }

void Sha256::Add(std::string_view bytes) {
  av_sha_update(ctx_, reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
}

void Sha256::AddField(std::string_view label, std::string_view value) {
  Add(label);
  Add("=" + std::to_string(value.size()) + ":");
  Add(value);
  Add(";");
}

std::string Sha256::HexDigest() {
  uint8_t digest[32];
  av_sha_final(ctx_, digest);
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  for (uint8_t b : digest) out += {kHex[b >> 4], kHex[b & 15]};
  return out;
}

Status HashWholeFile(Sha256& hash, const std::string& label, const std::string& path) {
  ARCO_ASSIGN_OR_RETURN(const std::string bytes, ReadFileToString(path));
  hash.AddField(label, bytes);
  return Status::Ok();
}

namespace {

// Size, first and last `sample` bytes of one file.
Status HashFileEnds(Sha256& hash,
                    const std::string& label,
                    const std::string& path,
                    int64_t sample) {
  std::ifstream in(path, std::ios::binary);
  std::error_code ec;
  const auto size = static_cast<int64_t>(fs::file_size(path, ec));
  if (!in || ec) return Status::Error(path + ": cannot read the video");
  std::string head(static_cast<size_t>(std::min(size, sample)), '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  const int64_t tail_size = std::min(size, sample);
  std::string tail(static_cast<size_t>(tail_size), '\0');
  in.seekg(size - tail_size);
  in.read(tail.data(), static_cast<std::streamsize>(tail.size()));
  if (!in) return Status::Error(path + ": cannot read the video");
  hash.AddField(label + ".size", std::to_string(size));
  hash.AddField(label + ".head", head);
  hash.AddField(label + ".tail", tail);
  return Status::Ok();
}

}  // namespace

Status HashVideoSource(Sha256& hash,
                       const std::string& label,
                       const std::string& path,
                       int64_t sample_bytes) {
  std::error_code ec;
  if (!fs::is_directory(path, ec)) return HashFileEnds(hash, label, path, sample_bytes);
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(path, ec)) {
    if (e.is_regular_file()) names.push_back(e.path().filename().string());
  }
  if (ec) return Status::Error(path + ": cannot list the image folder");
  std::sort(names.begin(), names.end());
  hash.AddField(label + ".images", std::to_string(names.size()));
  for (const auto& n : names) {
    ARCO_RETURN_IF_ERROR(HashFileEnds(hash, label + "/" + n, JoinPath(path, n), 4096));
  }
  return Status::Ok();
}

VideoCacheEntry CacheEntryPaths(const std::string& cache_dir, const std::string& key) {
  return {JoinPath(cache_dir, key + ".webm"), JoinPath(cache_dir, key + ".json")};
}

StatusOr<int> EvictVideoCache(const std::string& cache_dir,
                              int64_t max_bytes,
                              const std::set<std::string>& keep) {
  struct Entry {
    fs::file_time_type mtime;
    std::string key;
    int64_t bytes;
  };
  std::vector<Entry> entries;
  int64_t total = 0;
  std::error_code ec;
  const auto day_ago = fs::file_time_type::clock::now() - std::chrono::hours(24);
  for (const auto& e : fs::directory_iterator(cache_dir, ec)) {
    if (!e.is_regular_file()) continue;
    const std::string name = e.path().filename().string();
    const auto mtime = e.last_write_time();
    if (name[0] == '.') {  // a temporary: an encode in progress, or one interrupted
      if (mtime < day_ago) fs::remove(e.path(), ec);
      continue;
    }
    if (e.path().extension() != ".webm") continue;
    const std::string key = e.path().stem().string();
    int64_t bytes = static_cast<int64_t>(e.file_size());
    std::error_code side_ec;
    const auto side = fs::file_size(CacheEntryPaths(cache_dir, key).sidecar, side_ec);
    if (!side_ec) bytes += static_cast<int64_t>(side);
    entries.push_back({mtime, key, bytes});
    total += bytes;
  }
  if (ec) return Status::Error(cache_dir + ": cannot list the video cache");
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return a.mtime != b.mtime ? a.mtime < b.mtime : a.key < b.key;
  });
  int removed = 0;
  for (const auto& e : entries) {
    if (total <= max_bytes) break;
    if (keep.count(e.key)) continue;
    const VideoCacheEntry paths = CacheEntryPaths(cache_dir, e.key);
    // The sidecar first: a video without one is never taken.
    fs::remove(paths.sidecar, ec);
    fs::remove(paths.video, ec);
    if (ec) return Status::Error(paths.video + ": cannot remove from the video cache");
    total -= e.bytes;
    ++removed;
  }
  return removed;
}

}  // namespace arco::view
