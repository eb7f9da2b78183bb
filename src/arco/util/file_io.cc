#include "arco/util/file_io.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace arco {

namespace fs = std::filesystem;

StatusOr<std::string> ReadFileToString(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return Status::Error(path + ": file not found");
  if (fs::is_directory(path, ec)) return Status::Error(path + ": is a directory, expected a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": cannot open: " + std::strerror(errno));
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) return Status::Error(path + ": read error");
  return ss.str();
}

Status AtomicWriteWith(const std::string& path,
                       const std::function<Status(std::ostream&)>& writer) {
  const fs::path target(path);
  std::error_code ec;
  if (target.has_parent_path() && !fs::exists(target.parent_path(), ec)) {
    return Status::Error(path + ": output folder " + target.parent_path().string() +
                         " does not exist");
  }
  const std::string tmp = path + ".tmp-" + std::to_string(::getpid());
  Status status;
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return Status::Error(path + ": cannot write: " + std::strerror(errno));
    status = writer(out);
    out.flush();
    if (status.ok() && !out.good()) status = Status::Error(path + ": write failed (disk full?)");
  }
  if (!status.ok()) {
    fs::remove(tmp, ec);
    return status;
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    return Status::Error(path + ": cannot rename temporary file into place: " + ec.message());
  }
  return Status::Ok();
}

Status AtomicWriteFile(const std::string& path, const std::string& contents) {
  return AtomicWriteWith(path, [&](std::ostream& out) {
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    return Status::Ok();
  });
}

Status MakeDirectories(const std::string& path) {
  std::error_code ec;
  fs::create_directories(path, ec);
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

}  // namespace arco
