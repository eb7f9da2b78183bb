#include "arco/util/fingerprint.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <memory>
#include <vector>

#include "arco/util/check.h"

extern "C" {
#include <libavutil/mem.h>
#include <libavutil/murmur3.h>
}

namespace arco {
namespace {

struct Murmur3Free {
  void operator()(AVMurMur3* c) const { av_free(c); }
};
using Murmur3 = std::unique_ptr<AVMurMur3, Murmur3Free>;

Murmur3 NewHash() {
  Murmur3 hash(av_murmur3_alloc());
  ARCO_CHECK(hash != nullptr);
  av_murmur3_init(hash.get());  // the built-in seed: the same fingerprint in every process
  return hash;
}

std::string FinishHex(AVMurMur3* hash) {
  uint8_t digest[16];
  av_murmur3_final(hash, digest);
  static constexpr char kHex[] = "0123456789abcdef";
  std::string hex;
  for (uint8_t b : digest) {
    hex += kHex[b >> 4];
    hex += kHex[b & 15];
  }
  return hex;
}

struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

Fingerprint FingerprintBytes(std::string_view bytes) {
  Murmur3 hash = NewHash();
  av_murmur3_update(hash.get(), reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
  return {static_cast<int64_t>(bytes.size()), FinishHex(hash.get())};
}

StatusOr<Fingerprint> FingerprintFile(const std::string& path) {
  auto system_error = [&](const char* what) {
    const int err = errno;
    return Status::Error(path + ": " + what + ": " + std::strerror(err));
  };
  Fd file;
  file.fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (file.fd < 0) return system_error("cannot open");
  struct stat st {};
  if (::fstat(file.fd, &st) != 0) return system_error("cannot stat");
  if (!S_ISREG(st.st_mode)) return Status::Error(path + ": not a file");
  Murmur3 hash = NewHash();
  std::vector<uint8_t> buffer(size_t{1} << 20);
  int64_t size = 0;
  for (;;) {
    const ssize_t n = ::read(file.fd, buffer.data(), buffer.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      return system_error("cannot read");
    }
    if (n == 0) break;
    av_murmur3_update(hash.get(), buffer.data(), static_cast<size_t>(n));
    size += n;
  }
  return Fingerprint{size, FinishHex(hash.get())};
}

}  // namespace arco
