#include "arco/util/atomic_dir.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"
#include "arco/util/stats.h"

namespace arco {
namespace {

TEST(AtomicWriteDirectory, ReplacesTheFolderWhole) {
  testing::TempDir tmp;
  const std::string dir = tmp / "stage";
  ASSERT_TRUE(MakeDirectories(dir).ok());
  ASSERT_TRUE(AtomicWriteFile(JoinPath(dir, "old.txt"), "old").ok());
  ASSERT_TRUE(AtomicWriteDirectory(dir, [](const std::string& t) {
                return AtomicWriteFile(JoinPath(t, "new.txt"), "new");
              }).ok());
  EXPECT_TRUE(FileExists(JoinPath(dir, "new.txt")));
  EXPECT_FALSE(FileExists(JoinPath(dir, "old.txt")));  // replaced, not merged
  for (const auto& e : std::filesystem::directory_iterator(tmp.path())) {
    EXPECT_EQ(e.path().filename().string(), "stage");  // no temporary left behind
  }
}

TEST(AtomicWriteDirectory, AFailedWriteLeavesTheOldFolder) {
  testing::TempDir tmp;
  const std::string dir = tmp / "stage";
  ASSERT_TRUE(MakeDirectories(dir).ok());
  ASSERT_TRUE(AtomicWriteFile(JoinPath(dir, "old.txt"), "old").ok());
  const Status s = AtomicWriteDirectory(dir, [](const std::string& t) {
    EXPECT_TRUE(AtomicWriteFile(JoinPath(t, "partial.txt"), "x").ok());
    return Status::Error("disk full");
  });
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(s.message(), "disk full");
  EXPECT_TRUE(FileExists(JoinPath(dir, "old.txt")));
  EXPECT_FALSE(FileExists(JoinPath(dir, "partial.txt")));
  int entries = 0;
  for (const auto& e : std::filesystem::directory_iterator(tmp.path())) {
    (void)e;
    ++entries;
  }
  EXPECT_EQ(entries, 1);
}

TEST(Median, OddEvenAndEmpty) {
  EXPECT_DOUBLE_EQ(Median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_DOUBLE_EQ(Median({4.0, 1.0, 3.0, 2.0}), 2.5);
  EXPECT_TRUE(std::isnan(Median({})));
}

}  // namespace
}  // namespace arco
