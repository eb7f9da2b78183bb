#include "arco/util/atomic_dir.h"

#include <unistd.h>

#include <filesystem>
#include <system_error>

#include "arco/util/file_io.h"

namespace arco {

Status AtomicWriteDirectory(const std::string& dir,
                            const std::function<Status(const std::string& tmp_dir)>& write) {
  namespace fs = std::filesystem;
  const fs::path final_path(dir);
  const fs::path parent = final_path.parent_path();
  if (!parent.empty()) ARCO_RETURN_IF_ERROR(MakeDirectories(parent.string()));
  const std::string tmp_dir =
      (parent / ("." + final_path.filename().string() + ".tmp-" + std::to_string(::getpid())))
          .string();
  std::error_code ec;
  fs::remove_all(tmp_dir, ec);
  ARCO_RETURN_IF_ERROR(MakeDirectories(tmp_dir));
  Status status = write(tmp_dir);
  if (status.ok()) {
    fs::remove_all(dir, ec);
    fs::rename(tmp_dir, dir, ec);
    if (ec) status = Status::Error(dir + ": cannot move results into place (" + ec.message() + ")");
  }
  if (!status.ok()) fs::remove_all(tmp_dir, ec);
  return status;
}

}  // namespace arco
