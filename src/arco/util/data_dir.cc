#include "arco/util/data_dir.h"

#include <cstdlib>
#include <filesystem>
#include <system_error>

#ifndef ARCO_DATA_DIR_FROM_BIN
#error "ARCO_DATA_DIR_FROM_BIN must be defined by the build (src/arco/util/CMakeLists.txt)"
#endif

namespace arco {
namespace fs = std::filesystem;

namespace {

std::string EnvDataDir() {
  const char* env = std::getenv(kDataDirEnv);
  return env != nullptr ? std::string(env) : std::string();
}

}  // namespace

std::string ExecutablePath() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : exe.string();
}

std::string InstalledDataDir(const std::string& executable) {
  if (executable.empty()) return "";
  const fs::path dir =
      (fs::path(executable).parent_path() / ARCO_DATA_DIR_FROM_BIN).lexically_normal();
  std::error_code ec;
  return fs::is_directory(dir, ec) ? dir.string() : std::string();
}

std::string DataDir() {
  const std::string env = EnvDataDir();
  if (!env.empty()) return env;
  return InstalledDataDir(ExecutablePath());
}

std::string DataPath(const std::string& relative, const std::string& build_tree_path) {
  const std::string dir = DataDir();
  if (dir.empty()) return build_tree_path;
  return (fs::path(dir) / relative).string();
}

std::string DataDirHint() {
  if (!EnvDataDir().empty()) {
    return std::string("the data folder is $") + kDataDirEnv + " (or --data-dir)";
  }
  if (!DataDir().empty()) {
    return std::string("the installed data folder; $") + kDataDirEnv +
           " or `arco --data-dir DIR` names another";
  }
  return std::string("the source tree's; $") + kDataDirEnv +
         " or `arco --data-dir DIR` names an installed data folder";
}

}  // namespace arco
