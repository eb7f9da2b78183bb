#include "arco/util/output_set.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "arco/testing/temp_dir.h"
#include "arco/util/atomic_dir.h"
#include "arco/util/file_io.h"

namespace arco {
namespace {

namespace fs = std::filesystem;

std::set<std::string> Entries(const std::string& dir) {
  std::set<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.insert(e.path().filename().string());
  return out;
}

std::string Read(const std::string& path) {
  auto s = ReadFileToString(path);
  return s.ok() ? *s : "<" + s.status().message() + ">";
}

Status WriteNew(const std::string& dir) { return AtomicWriteFile(JoinPath(dir, "new.txt"), "new"); }

TEST(NormalizeOutputPath, TrailingSlashNamesTheSameFolder) {
  EXPECT_EQ(NormalizeOutputPath("cap3/"), "cap3");
  EXPECT_EQ(NormalizeOutputPath("cap3//"), "cap3");
  EXPECT_EQ(NormalizeOutputPath("a/./b/"), "a/b");
  EXPECT_EQ(NormalizeOutputPath("/"), "/");
  EXPECT_EQ(NormalizeOutputPath(""), "");
}

TEST(AtomicWriteDirectory, TrailingSlashWritesTheFolder) {
  testing::TempDir tmp;
  ASSERT_TRUE(AtomicWriteDirectory(tmp / "cap/", FolderReplace{}, WriteNew).ok());
  EXPECT_EQ(Read(tmp / "cap/new.txt"), "new");
  EXPECT_EQ(Entries(tmp.path()), std::set<std::string>{"cap"});
}

TEST(AtomicWriteDirectory, TrailingSlashReplacesAnExistingFolder) {
  testing::TempDir tmp;
  ASSERT_TRUE(AtomicWriteFile(tmp / "old.txt", "x").ok());
  ASSERT_TRUE(MakeDirectories(tmp / "cap").ok());
  ASSERT_TRUE(AtomicWriteFile(tmp / "cap/capture.json", "old").ok());
  FolderReplace r{true, "capture.json", "capture"};
  ASSERT_TRUE(AtomicWriteDirectory(tmp / "cap/", r, [](const std::string& d) {
                return AtomicWriteFile(JoinPath(d, "capture.json"), "new");
              }).ok());
  EXPECT_EQ(Read(tmp / "cap/capture.json"), "new");
  EXPECT_EQ(Entries(tmp.path()), (std::set<std::string>{"cap", "old.txt"}));
}

TEST(AtomicWriteDirectory, ExistingFolderNeedsOverwrite) {
  testing::TempDir tmp;
  ASSERT_TRUE(MakeDirectories(tmp / "cap").ok());
  ASSERT_TRUE(AtomicWriteFile(tmp / "cap/capture.json", "old").ok());
  const Status s =
      AtomicWriteDirectory(tmp / "cap", FolderReplace{false, "capture.json", "capture"}, WriteNew);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message(),
            tmp / "cap" + ": capture exists and is not empty (--overwrite replaces it)");
  EXPECT_EQ(Read(tmp / "cap/capture.json"), "old");
  EXPECT_EQ(Entries(tmp.path()), std::set<std::string>{"cap"});
}

TEST(AtomicWriteDirectory, EmptyFolderIsReplacedWithoutOverwrite) {
  testing::TempDir tmp;
  ASSERT_TRUE(MakeDirectories(tmp / "cap").ok());
  ASSERT_TRUE(AtomicWriteDirectory(tmp / "cap/", FolderReplace{}, WriteNew).ok());
  EXPECT_EQ(Read(tmp / "cap/new.txt"), "new");
}

TEST(AtomicWriteDirectory, OverwriteKeepsAFolderOfAnotherKind) {
  testing::TempDir tmp;
  ASSERT_TRUE(MakeDirectories(tmp / "photos").ok());
  ASSERT_TRUE(AtomicWriteFile(tmp / "photos/a.jpg", "precious").ok());
  const Status s = AtomicWriteDirectory(
      tmp / "photos", FolderReplace{true, "capture.json", "capture"}, WriteNew);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("no capture.json"), std::string::npos) << s.message();
  EXPECT_EQ(Read(tmp / "photos/a.jpg"), "precious");
  EXPECT_EQ(Entries(tmp.path()), std::set<std::string>{"photos"});
}

TEST(AtomicWriteDirectory, FailureMidWriteKeepsTheOldFolder) {
  testing::TempDir tmp;
  ASSERT_TRUE(MakeDirectories(tmp / "cap").ok());
  ASSERT_TRUE(AtomicWriteFile(tmp / "cap/capture.json", "old").ok());
  const Status s = AtomicWriteDirectory(
      tmp / "cap/", FolderReplace{true, "capture.json", "capture"}, [](const std::string& d) {
        EXPECT_TRUE(AtomicWriteFile(JoinPath(d, "capture.json"), "half").ok());
        return Status::Error("disk full");
      });
  EXPECT_EQ(s.message(), "disk full");
  EXPECT_EQ(Read(tmp / "cap/capture.json"), "old");
  EXPECT_EQ(Entries(tmp / "cap"), std::set<std::string>{"capture.json"});
  EXPECT_EQ(Entries(tmp.path()), std::set<std::string>{"cap"});
}

TEST(AtomicWriteDirectory, FailureToMoveInRestoresTheOldFolder) {
  testing::TempDir tmp;
  ASSERT_TRUE(MakeDirectories(tmp / "cap").ok());
  ASSERT_TRUE(AtomicWriteFile(tmp / "cap/capture.json", "old").ok());
  // The temporary vanishing before the move stands for any failing rename.
  const Status s = AtomicWriteDirectory(
      tmp / "cap", FolderReplace{true, "capture.json", "capture"}, [](const std::string& d) {
        fs::remove_all(d);
        return Status::Ok();
      });
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message(), tmp / "cap" + ": cannot move into place: No such file or directory");
  EXPECT_EQ(Read(tmp / "cap/capture.json"), "old");
  EXPECT_EQ(Entries(tmp.path()), std::set<std::string>{"cap"});
}

TEST(AtomicWriteDirectory, ParentUnderAFileIsAClearError) {
  testing::TempDir tmp;
  ASSERT_TRUE(AtomicWriteFile(tmp / "file", "x").ok());
  const Status s = AtomicWriteDirectory(tmp / "file/sub/cap", FolderReplace{}, WriteNew);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message(),
            tmp / "file/sub/cap: cannot create folder: " + tmp / "file is not a folder");
  const Status f = AtomicWriteDirectory(tmp / "file", FolderReplace{}, WriteNew);
  EXPECT_EQ(f.message(), tmp / "file: exists and is not a folder");
}

TEST(AtomicWriteDirectory, ReadOnlyParentNamesThePath) {
  if (::geteuid() == 0) GTEST_SKIP() << "root writes into read-only folders";
  testing::TempDir tmp;
  ASSERT_TRUE(MakeDirectories(tmp / "ro").ok());
  fs::permissions(tmp / "ro", fs::perms::owner_read | fs::perms::owner_exec);
  const Status s = AtomicWriteDirectory(tmp / "ro/cap", FolderReplace{}, WriteNew);
  fs::permissions(tmp / "ro", fs::perms::owner_all);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message(),
            tmp / "ro/cap" + ": cannot create folder in " + tmp / "ro: Permission denied");
}

TEST(AtomicWriteFile, ExistingFolderAsFilePathIsAnError) {
  testing::TempDir tmp;
  ASSERT_TRUE(MakeDirectories(tmp / "out").ok());
  EXPECT_EQ(AtomicWriteFile(tmp / "out", "x").message(),
            tmp / "out: is a folder; expected a file path");
  EXPECT_EQ(AtomicWriteFile(tmp / "new/", "x").message(),
            tmp / "new/: names a folder; expected a file path");
  EXPECT_EQ(AtomicWriteFile(tmp / "nodir/p.csv", "x").message(),
            tmp / "nodir/p.csv: output folder " + tmp / "nodir does not exist");
  EXPECT_EQ(Entries(tmp.path()), std::set<std::string>{"out"});
}

TEST(AtomicWriteFile, ReplacesAnExistingFile) {
  testing::TempDir tmp;
  ASSERT_TRUE(AtomicWriteFile(tmp / "p.csv", "old").ok());
  ASSERT_TRUE(AtomicWriteFile(tmp / "p.csv", "new").ok());
  EXPECT_EQ(Read(tmp / "p.csv"), "new");
  EXPECT_EQ(Entries(tmp.path()), std::set<std::string>{"p.csv"});
}

TEST(OutputSet, ASecondBadOutputIsFoundBeforeAnyWork) {
  testing::TempDir tmp;
  ASSERT_TRUE(AtomicWriteFile(tmp / "p.csv", "old").ok());
  OutputSet outputs;
  ASSERT_TRUE(outputs.AddFile(tmp / "p.csv").ok());
  const auto notes = outputs.AddFile(tmp / "nodir/n.csv");
  ASSERT_FALSE(notes.ok());
  EXPECT_EQ(notes.status().message(),
            tmp / "nodir/n.csv: output folder " + tmp / "nodir does not exist");
}

TEST(OutputSet, NothingIsWrittenUntilCommitAndTemporariesGoOnFailure) {
  testing::TempDir tmp;
  ASSERT_TRUE(AtomicWriteFile(tmp / "p.csv", "old").ok());
  {
    OutputSet outputs;
    auto a = outputs.AddFile(tmp / "p.csv");
    auto b = outputs.AddFolder(tmp / "dir", FolderReplace{});
    ASSERT_TRUE(a.ok() && b.ok());
    ASSERT_TRUE(AtomicWriteFile(*a, "new").ok());
    EXPECT_EQ(Read(tmp / "p.csv"), "old");
    // Destroyed without Commit: a failed command.
  }
  EXPECT_EQ(Entries(tmp.path()), std::set<std::string>{"p.csv"});
  EXPECT_EQ(Read(tmp / "p.csv"), "old");
}

TEST(OutputSet, AFailedMoveRollsBackTheOutputsAlreadyMoved) {
  testing::TempDir tmp;
  ASSERT_TRUE(AtomicWriteFile(tmp / "a.csv", "old a").ok());
  ASSERT_TRUE(MakeDirectories(tmp / "b").ok());
  ASSERT_TRUE(AtomicWriteFile(tmp / "b/x", "old b").ok());
  OutputSet outputs;
  auto a = outputs.AddFile(tmp / "a.csv");
  auto b = outputs.AddFolder(tmp / "b/", FolderReplace{true, "x", "folder"});
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_TRUE(AtomicWriteFile(*a, "new a").ok());
  fs::remove_all(*b);  // the second move will fail
  const Status s = outputs.Commit();
  EXPECT_EQ(s.message(), tmp / "b: cannot move into place: No such file or directory");
  EXPECT_EQ(Read(tmp / "a.csv"), "old a");
  EXPECT_EQ(Read(tmp / "b/x"), "old b");
  EXPECT_EQ(Entries(tmp.path()), (std::set<std::string>{"a.csv", "b"}));
}

TEST(OutputSet, CommitWritesEveryOutput) {
  testing::TempDir tmp;
  OutputSet outputs;
  auto a = outputs.AddFile(tmp / "a.csv");
  auto b = outputs.AddFolder(tmp / "sub/b", FolderReplace{});
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_FALSE(outputs.AddFile(tmp / "a.csv").ok());  // the same output twice
  ASSERT_TRUE(AtomicWriteFile(*a, "a").ok());
  ASSERT_TRUE(WriteNew(*b).ok());
  ASSERT_TRUE(outputs.Commit().ok());
  EXPECT_EQ(Read(tmp / "a.csv"), "a");
  EXPECT_EQ(Read(tmp / "sub/b/new.txt"), "new");
  EXPECT_EQ(Entries(tmp.path()), (std::set<std::string>{"a.csv", "sub"}));
}

TEST(OutputSet, RemovalsGoWithTheCommit) {
  testing::TempDir tmp;
  ASSERT_TRUE(MakeDirectories(tmp / "later").ok());
  ASSERT_TRUE(AtomicWriteFile(tmp / "later/x", "stale").ok());
  ASSERT_TRUE(AtomicWriteFile(tmp / "notes.csv", "stale").ok());
  OutputSet outputs;
  auto a = outputs.AddFile(tmp / "a.csv");
  ASSERT_TRUE(a.ok());
  ASSERT_TRUE(outputs.AddRemoval(tmp / "later/").ok());
  ASSERT_TRUE(outputs.AddRemoval(tmp / "notes.csv").ok());
  ASSERT_TRUE(outputs.AddRemoval(tmp / "never-there").ok());  // absent: nothing to do
  EXPECT_FALSE(outputs.AddRemoval(tmp / "later").ok());       // the same output twice
  EXPECT_FALSE(outputs.AddRemoval(tmp / "a.csv").ok());
  ASSERT_TRUE(AtomicWriteFile(*a, "a").ok());
  // Nothing goes before the commit.
  EXPECT_EQ(Read(tmp / "later/x"), "stale");
  ASSERT_TRUE(outputs.Commit().ok());
  EXPECT_EQ(Entries(tmp.path()), (std::set<std::string>{"a.csv"}));
}

TEST(OutputSet, AFailedMovePutsTheRemovalsBack) {
  testing::TempDir tmp;
  ASSERT_TRUE(MakeDirectories(tmp / "later").ok());
  ASSERT_TRUE(AtomicWriteFile(tmp / "later/x", "stale").ok());
  OutputSet outputs;
  ASSERT_TRUE(outputs.AddRemoval(tmp / "later").ok());
  auto b = outputs.AddFolder(tmp / "b", FolderReplace{});
  ASSERT_TRUE(b.ok());
  fs::remove_all(*b);  // the move of b will fail, after the removal was moved aside
  EXPECT_FALSE(outputs.Commit().ok());
  EXPECT_EQ(Read(tmp / "later/x"), "stale");
  EXPECT_EQ(Entries(tmp.path()), (std::set<std::string>{"later"}));
}

// A pid no process has: a child that has exited and been reaped.
long DeadPid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return child;
}

// What a killed command leaves (its temporary, or its old output moved aside after the new
// one was in) goes the next time an output is written into that folder, whatever its
// name; a live process's temporaries, entries that only look alike, and an old output
// whose new one never arrived stay.
TEST(OutputSet, StaleTemporariesOfDeadProcessesAreRemoved) {
  testing::TempDir tmp;
  const std::string dead = std::to_string(DeadPid());
  const std::string live = std::to_string(::getppid());
  for (const std::string& name : {".tmp-" + dead + ".result",
                                  ".old-" + dead + ".result",
                                  ".tmp-" + live + ".result",
                                  ".tmp-" + dead + ".other",
                                  ".old-" + dead + ".gone",
                                  ".old-" + dead + ".kept",
                                  std::string(".tmp-x1.result"),
                                  ".tmp-" + dead,
                                  ".tmp-" + dead + "."}) {
    ASSERT_TRUE(MakeDirectories(tmp / name).ok());
  }
  ASSERT_TRUE(MakeDirectories(tmp / "result").ok());
  ASSERT_TRUE(MakeDirectories(tmp / "kept").ok());
  ASSERT_TRUE(
      AtomicWriteDirectory(tmp / "result", FolderReplace{true, "", "folder"}, WriteNew).ok());
  EXPECT_EQ(Entries(tmp.path()),
            (std::set<std::string>{"result",
                                   "kept",
                                   ".tmp-" + live + ".result",
                                   ".old-" + dead + ".gone",
                                   ".tmp-x1.result",
                                   ".tmp-" + dead,
                                   ".tmp-" + dead + "."}));
  // The same for a file output.
  ASSERT_TRUE(AtomicWriteFile(tmp / ".tmp-" + dead + ".p.csv", "partial").ok());
  ASSERT_TRUE(AtomicWriteFile(tmp / "p.csv", "whole").ok());
  EXPECT_FALSE(fs::exists(tmp / ".tmp-" + dead + ".p.csv"));
  EXPECT_EQ(Read(tmp / "p.csv"), "whole");
}

// RemoveStaleTemporaries alone (the CLI calls it for every declared output at start):
// counts what it removed, and leaves the output itself and its siblings alone.
TEST(RemoveStaleTemporaries, CleansTheParentFolderOfDeadProcessesOnly) {
  testing::TempDir tmp;
  const std::string dead = std::to_string(DeadPid());
  const std::string live = std::to_string(::getpid());
  // Written directly: an OutputSet would clean the folder itself.
  std::ofstream(tmp / ".tmp-" + dead + ".a.npy") << "partial";
  ASSERT_TRUE(MakeDirectories(tmp / (".tmp-" + dead + ".cap") + "/truth").ok());
  std::ofstream(tmp / ".tmp-" + live + ".mine") << "in progress";
  std::ofstream(tmp / "m.wav") << "recording";
  EXPECT_EQ(RemoveStaleTemporaries(tmp / "out.csv"), 2);
  EXPECT_EQ(Entries(tmp.path()), (std::set<std::string>{".tmp-" + live + ".mine", "m.wav"}));
  EXPECT_EQ(RemoveStaleTemporaries(tmp / "out.csv"), 0);
  EXPECT_EQ(RemoveStaleTemporaries(tmp / "missing/out.csv"), 0);  // no such folder
}

}  // namespace
}  // namespace arco
