#include "arco/util/interrupt.h"

#include <pthread.h>
#include <semaphore.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <map>
#include <thread>

namespace arco {
namespace fs = std::filesystem;
namespace {

constexpr int kInterruptedExitStatus = 130;  // 128 + SIGINT, as shells report Ctrl-C

// Never destroyed: the cleanup thread may use them while the process exits.
struct State {
  std::mutex commit;  // HoldOffInterrupts; the cleanup thread takes it for good
  std::mutex paths_mutex;
  std::map<std::string, int> paths;  // path -> times tracked
  sem_t wake;
  std::atomic<bool> installed{false};
};
State& GetState() {
  static State* state = new State;
  return *state;
}

std::atomic<int> g_signal{0};

void OnSignal(int signal) {
  int none = 0;
  if (!g_signal.compare_exchange_strong(none, signal)) _exit(kInterruptedExitStatus);
  sem_post(&GetState().wake);
}

void Write(const std::string& text) {
  const ssize_t ignored = ::write(STDERR_FILENO, text.data(), text.size());
  (void)ignored;
}

[[noreturn]] void CleanUpAndExit() {
  State& state = GetState();
  while (sem_wait(&state.wake) != 0) {
  }
  state.commit.lock();  // never released: no output is moved into place after this
  std::map<std::string, int> paths;
  {
    std::lock_guard<std::mutex> lock(state.paths_mutex);
    paths = state.paths;
  }
  // The command's threads still run until _exit and may still create files in a temporary
  // folder while it is removed (remove_all then fails on a folder no longer empty), but
  // cannot bring back one that is gone: folders and temporaries are made only under the
  // commit lock, held here (MakeDirectories, OutputSet). Retry until each is gone.
  for (int pass = 0; pass < 200; ++pass) {
    bool any = false;
    for (const auto& [path, count] : paths) {
      std::error_code ec;
      fs::remove_all(path, ec);
      any = any || fs::exists(fs::symlink_status(path, ec));
    }
    if (!any) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  const char* name = g_signal.load() == SIGTERM ? "SIGTERM" : "SIGINT";
  Write(std::string(isatty(STDERR_FILENO) ? "\n" : "") + "arco: interrupted (" + name +
        "): the outputs being written were removed\n");
  _exit(kInterruptedExitStatus);
}

}  // namespace

void InstallInterruptCleanup() {
  State& state = GetState();
  if (state.installed.exchange(true)) return;
  sem_init(&state.wake, 0, 0);
  sigset_t signals, previous;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  // The cleanup thread inherits the blocked mask: the handler runs on another thread, and
  // a thread that waits for the signals itself (sigtimedwait) is not raced.
  pthread_sigmask(SIG_BLOCK, &signals, &previous);
  std::thread(CleanUpAndExit).detach();
  pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  struct sigaction action;
  std::memset(&action, 0, sizeof(action));
  action.sa_handler = OnSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

bool Interrupted() { return g_signal.load() != 0; }

void WaitIfInterrupted() {
  if (!Interrupted()) return;
  for (;;) pause();
}

// Absolute, so that the cleanup does not depend on the working folder.
std::string Absolute(const std::string& path) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(path, ec);
  return ec ? path : absolute.string();
}

void TrackTemporary(const std::string& path) {
  State& state = GetState();
  const std::string key = Absolute(path);
  std::lock_guard<std::mutex> lock(state.paths_mutex);
  ++state.paths[key];
}

void UntrackTemporary(const std::string& path) {
  State& state = GetState();
  const std::string key = Absolute(path);
  std::lock_guard<std::mutex> lock(state.paths_mutex);
  auto it = state.paths.find(key);
  if (it != state.paths.end() && --it->second <= 0) state.paths.erase(it);
}

std::unique_lock<std::mutex> HoldOffInterrupts() {
  return std::unique_lock<std::mutex>(GetState().commit);
}

}  // namespace arco
