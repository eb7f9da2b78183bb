#include "arco/util/interrupt.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <set>
#include <string>
#include <thread>

#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"
#include "arco/util/output_set.h"

namespace arco {
namespace {

namespace fs = std::filesystem;

std::set<std::string> Entries(const std::string& dir) {
  std::set<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.insert(e.path().filename().string());
  return out;
}

// Runs `body` in a child process with the cleanup installed, sends it `signal` from
// inside, and returns the child's exit status (-1 when it did not exit normally).
int InterruptedChild(int signal, const std::function<void()>& body) {
  const pid_t child = ::fork();
  if (child == 0) {
    InstallInterruptCleanup();
    body();
    ::kill(::getpid(), signal);
    for (;;) ::pause();  // the cleanup thread ends the process
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// An interrupt removes the temporaries of the outputs being written (a folder with files
// in it, a file), keeps the outputs already committed, and exits with 130.
TEST(InterruptCleanup, RemovesTheTemporariesAndExits130) {
  for (const int signal : {SIGINT, SIGTERM}) {
    testing::TempDir tmp;
    const int status = InterruptedChild(signal, [&] {
      ASSERT_TRUE(AtomicWriteFile(tmp / "done.csv", "whole").ok());
      static OutputSet outputs;  // never committed: the interrupt comes first
      auto folder = outputs.AddFolder(tmp / "cap", FolderReplace{});
      auto file = outputs.AddFile(tmp / "p.csv");
      ASSERT_TRUE(folder.ok() && file.ok());
      ASSERT_TRUE(MakeDirectories(*folder + "/truth").ok());
      ASSERT_TRUE(AtomicWriteFile(*folder + "/truth/points.npy", "partial").ok());
      ASSERT_TRUE(AtomicWriteFile(*file, "partial").ok());
    });
    EXPECT_EQ(status, 130) << "signal " << signal;
    EXPECT_EQ(Entries(tmp.path()), (std::set<std::string>{"done.csv"})) << "signal " << signal;
  }
}

// A thread that keeps making folders inside a temporary folder while the interrupt's
// cleanup removes it (as `arco run`'s stages write into its result folder) cannot bring the
// temporary back: every run of the race leaves only the committed output.
TEST(InterruptCleanup, AFolderMadeInsideARemovedTemporaryDoesNotBringItBack) {
  for (int attempt = 0; attempt < 10; ++attempt) {
    testing::TempDir tmp;
    const int status = InterruptedChild(SIGTERM, [&] {
      ASSERT_TRUE(AtomicWriteFile(tmp / "done.csv", "whole").ok());
      static OutputSet outputs;  // never committed: the interrupt comes first
      static std::string folder;
      auto made = outputs.AddFolder(tmp / "res", FolderReplace{});
      ASSERT_TRUE(made.ok());
      folder = *made;
      std::thread([] {
        for (long i = 0;; ++i) {
          (void)MakeDirectories(folder + "/stage" + std::to_string(i % 7) + "/sub");
        }
      }).detach();
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    });
    EXPECT_EQ(status, 130) << "attempt " << attempt;
    EXPECT_EQ(Entries(tmp.path()), (std::set<std::string>{"done.csv"})) << "attempt " << attempt;
  }
}

// Without the cleanup installed nothing is tracked for a signal, and Interrupted() stays
// false in this (test) process.
TEST(InterruptCleanup, NotInstalledMeansNotInterrupted) {
  EXPECT_FALSE(Interrupted());
  WaitIfInterrupted();  // returns at once
}

}  // namespace
}  // namespace arco
