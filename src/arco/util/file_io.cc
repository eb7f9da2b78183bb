#include "arco/util/file_io.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>

#include "arco/util/interrupt.h"
#include "arco/util/output_set.h"

namespace arco {

namespace fs = std::filesystem;

StatusOr<std::string> ReadFileToString(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return Status::Error(path + ": file not found");
  if (fs::is_directory(path, ec)) return Status::Error(path + ": is a directory, expected a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": cannot open: " + std::strerror(errno));
  // One allocation and one read when the size is known (a 59 MB keypoints2d.npy took
  // 0.3 s through a growing ostringstream and its copy); a stream of unknown size
  // (a pipe) is read to its end.
  std::string bytes;
  const std::uintmax_t size = fs::file_size(path, ec);
  if (!ec && fs::is_regular_file(path, ec)) {
    bytes.resize(static_cast<size_t>(size));
    in.read(bytes.data(), static_cast<std::streamsize>(size));
    bytes.resize(static_cast<size_t>(in.gcount()));
    if (in.bad()) return Status::Error(path + ": read error");
    if (in.eof() || in.peek() == std::char_traits<char>::eof()) return bytes;
    in.clear();
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) return Status::Error(path + ": read error");
  return bytes + ss.str();
}

struct FileBytes::Mapping {
  void* address = nullptr;
  size_t size = 0;
  ~Mapping() {
    if (address != nullptr) munmap(address, size);
  }
};

StatusOr<FileBytes> FileBytes::Open(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return Status::Error(path + ": file not found");
  if (fs::is_directory(path, ec)) return Status::Error(path + ": is a directory, expected a file");
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return Status::Error(path + ": cannot open: " + std::strerror(errno));
  FileBytes out;
  struct stat st {};
  if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
    void* a = ::mmap(nullptr, static_cast<size_t>(st.st_size), PROT_READ, MAP_PRIVATE, fd, 0);
    if (a != MAP_FAILED) {
      ::close(fd);
      auto m = std::make_shared<Mapping>();
      m->address = a;
      m->size = static_cast<size_t>(st.st_size);
      out.view_ = std::string_view(static_cast<const char*>(a), m->size);
      out.mapping_ = std::move(m);
      return out;
    }
  }
  // Not mappable (a pipe, an empty file, a file system without mmap): read from the same
  // descriptor to its end (a pipe's bytes would be lost by opening it again).
  auto copy = std::make_shared<std::string>();
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof(buffer));
    if (n == 0) break;
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      ::close(fd);
      return Status::Error(path + ": read error: " + std::strerror(err));
    }
    copy->append(buffer, static_cast<size_t>(n));
  }
  ::close(fd);
  out.view_ = *copy;
  out.copy_ = std::move(copy);
  return out;
}

Status AtomicWriteWith(const std::string& path,
                       const std::function<Status(std::ostream&)>& writer) {
  OutputSet outputs;
  ARCO_ASSIGN_OR_RETURN(const std::string tmp, outputs.AddFile(path));
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      const int err = errno;
      return Status::Error(path + ": cannot write: " + std::strerror(err));
    }
    ARCO_RETURN_IF_ERROR(writer(out));
    out.flush();
    if (!out.good()) return Status::Error(path + ": write failed (disk full?)");
  }
  return outputs.Commit();
}

Status AtomicWriteFile(const std::string& path, const std::string& contents) {
  return AtomicWriteWith(path, [&](std::ostream& out) {
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    return Status::Ok();
  });
}

Status MakeDirectories(const std::string& path) {
  std::error_code ec;
  {
    // Not while an interrupt's cleanup removes the temporaries: a folder made inside a
    // removed temporary would bring it back (util/interrupt.h).
    const std::unique_lock<std::mutex> no_interrupt = HoldOffInterrupts();
    fs::create_directories(path, ec);
  }
  if (ec) return Status::Error(path + ": cannot create folder: " + ec.message());
  if (!fs::is_directory(path, ec)) return Status::Error(path + ": exists and is not a folder");
  return Status::Ok();
}

bool FileExists(const std::string& path) {
  std::error_code ec;
  return fs::exists(path, ec);
}

std::string JoinPath(const std::string& a, const std::string& b) {
  return (fs::path(a) / fs::path(b)).string();
}

std::string PathRelativeTo(const std::string& path, const std::string& base) {
  if (fs::path(path).is_absolute()) return NormalizeOutputPath(path);
  const fs::path from = fs::absolute(base).lexically_normal();
  const fs::path to = fs::absolute(path).lexically_normal();
  const fs::path relative = to.lexically_relative(from);
  std::string out = relative.empty() ? to.string() : relative.string();
  while (out.size() > 1 && out.back() == '/') out.pop_back();
  return out;
}

bool NaturalLess(const std::string& a, const std::string& b) {
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    const bool da = std::isdigit(static_cast<unsigned char>(a[i])) != 0;
    const bool db = std::isdigit(static_cast<unsigned char>(b[j])) != 0;
    if (da && db) {
      size_t ie = i, je = j;
      while (ie < a.size() && std::isdigit(static_cast<unsigned char>(a[ie]))) ++ie;
      while (je < b.size() && std::isdigit(static_cast<unsigned char>(b[je]))) ++je;
      size_t is = i, js = j;  // skip leading zeros, then longer is larger
      while (is + 1 < ie && a[is] == '0') ++is;
      while (js + 1 < je && b[js] == '0') ++js;
      const std::string_view na(a.data() + is, ie - is), nb(b.data() + js, je - js);
      if (na.size() != nb.size()) return na.size() < nb.size();
      if (na != nb) return na < nb;
      i = ie;
      j = je;
      continue;
    }
    if (a[i] != b[j]) return a[i] < b[j];
    ++i;
    ++j;
  }
  if (a.size() - i != b.size() - j) return a.size() - i < b.size() - j;
  return a < b;  // equal up to leading zeros: any fixed order
}

}  // namespace arco
