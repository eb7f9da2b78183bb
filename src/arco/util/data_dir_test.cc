#include "arco/util/data_dir.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <string>

#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"

namespace arco {
namespace {

// Sets an environment variable for one scope and restores the old value after.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    const char* old = std::getenv(name);
    had_ = old != nullptr;
    if (had_) old_ = old;
    if (value != nullptr) {
      setenv(name, value, 1);
    } else {
      unsetenv(name);
    }
  }
  ~ScopedEnv() {
    if (had_) {
      setenv(name_, old_.c_str(), 1);
    } else {
      unsetenv(name_);
    }
  }

 private:
  const char* name_;
  bool had_ = false;
  std::string old_;
};

TEST(DataDir, AnInstalledExecutableFindsShareArcoBesideItsBinFolder) {
  testing::TempDir tmp;
  ASSERT_TRUE(MakeDirectories(tmp / "prefix/bin").ok());
  EXPECT_EQ(InstalledDataDir(tmp / "prefix/bin/arco"), "");  // no share/arco: not installed
  ASSERT_TRUE(MakeDirectories(tmp / "prefix/share/arco").ok());
  EXPECT_EQ(InstalledDataDir(tmp / "prefix/bin/arco"), tmp / "prefix/share/arco");
  EXPECT_EQ(InstalledDataDir(""), "");
}

TEST(DataDir, TheEnvironmentOverridesAndABuildTreeArcoUsesTheCompiledInPath) {
  {
    ScopedEnv env(kDataDirEnv, "/opt/arco-data");
    EXPECT_EQ(DataDir(), "/opt/arco-data");
    EXPECT_EQ(DataPath("view/web", "/src/view/web"), "/opt/arco-data/view/web");
    EXPECT_NE(DataDirHint().find("ARCO_DATA_DIR"), std::string::npos);
  }
  ScopedEnv unset(kDataDirEnv, nullptr);
  // This test binary lives in BUILD/tests, with no share/arco beside it.
  EXPECT_EQ(DataDir(), "");
  EXPECT_EQ(DataPath("view/web", "/src/view/web"), "/src/view/web");
  EXPECT_NE(ExecutablePath().find("util_test"), std::string::npos);
}

}  // namespace
}  // namespace arco
