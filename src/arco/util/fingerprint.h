// A file's fingerprint: its size and a 128-bit hash of its bytes, to tell whether the file
// a result was made from is still the same (docs/architecture.md, "Results are tied to
// their inputs"). The hash is MurmurHash3 x64 128 (libavutil's av_murmur3 with its fixed
// seed 0x725acc55daddca55; the two 64-bit halves little-endian, as hex): not cryptographic, so it
// says "changed by accident" (an edit, a re-run, a replaced capture), not "tampered with"; at
// several GB/s it costs `arco run` about 20 ms for a 100 MB capture, so every reader can afford to
// re-hash instead of trusting a size + mtime shortcut (mtime survives `cp -p`, rsync and quick
// rewrites).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "arco/util/status.h"

namespace arco {

struct Fingerprint {
  int64_t size_bytes = 0;
  std::string murmur3;  // 32 lower-case hex digits

  bool operator==(const Fingerprint& other) const {
    return size_bytes == other.size_bytes && murmur3 == other.murmur3;
  }
  bool operator!=(const Fingerprint& other) const { return !(*this == other); }
};

// The fingerprint of `path`'s bytes, read in chunks (any size). Errors name the path and
// the system's reason (missing, a folder, unreadable).
StatusOr<Fingerprint> FingerprintFile(const std::string& path);

// The same of bytes in memory: FingerprintFile(path) == FingerprintBytes(contents).
Fingerprint FingerprintBytes(std::string_view bytes);

}  // namespace arco
