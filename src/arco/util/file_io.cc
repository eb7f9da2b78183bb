#include "arco/util/file_io.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "arco/util/output_set.h"

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
