// Temporary folders for tests: the one RAII helper, so no test hand-rolls mkdtemp or
// remove_all. ctest runs the tests of one binary as separate processes, possibly at the same
// time, so every folder carries the process id.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>

namespace arco::testing {

// A fresh, empty temporary folder, removed (with everything in it) when destroyed.
class TempDir {
 public:
  // Named after the running test (body or fixture constructor); a second one needs a name.
  TempDir() : TempDir(CurrentTestName()) {}
  // Named `name`, for a folder that outlives one test (a suite's or the process's shared
  // data, made before any test runs).
  explicit TempDir(std::string name) {
    // Parameterised tests are named "Suite/Name/0": one folder, not nested ones
    // that the destructor would only partly remove.
    std::replace(name.begin(), name.end(), '/', '_');
    path_ = (std::filesystem::temp_directory_path() /
             ("arco_test_" + std::to_string(::getpid()) + "_" + name))
                .string();
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::string& path() const { return path_; }
  std::string operator/(const std::string& name) const { return path_ + "/" + name; }

 private:
  static std::string CurrentTestName() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    if (info == nullptr) return "no_test";
    return std::string(info->test_suite_name()) + "_" + info->name();
  }

  std::string path_;
};

// One temporary folder for the whole test process (created on first use and
// removed when the process exits, so repeated test runs leave nothing behind).
inline std::string PerProcessTempDir() {
  struct Owned {
    std::string path = ::testing::TempDir() + "/arco-" + std::to_string(::getpid());
    Owned() { std::filesystem::create_directories(path); }
    ~Owned() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Owned dir;
  return dir.path;
}

}  // namespace arco::testing
