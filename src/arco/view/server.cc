#include "arco/view/server.h"

#include <httplib.h>
#include <pthread.h>
#include <signal.h>
#include <sys/socket.h>

#include <atomic>
#include <chrono>
#include <thread>

namespace arco::view {

Status ServeOptions::Validate() const {
  if (dir.empty()) return Status::Error("dir is empty");
  if (port < 0 || port > 65535) return Status::Error("port: not in [0, 65535]");
  if (!(exit_after_s >= 0 && exit_after_s <= 86400)) {
    return Status::Error("exit_after_s: not in [0, 86400]");
  }
  return Status::Ok();
}

Status ServeFolder(const ServeOptions& options, const std::function<void(int port)>& on_listening) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  httplib::Server server;
  // GET (and HEAD) of the folder's files only: the mount point serves nothing above `dir`
  // (httplib rejects paths with ".."), and every other method is answered 405.
  if (!server.set_mount_point("/", options.dir)) {
    return Status::Error(options.dir + ": not a folder to serve");
  }
  // No compression: on 127.0.0.1 it gains nothing, and httplib compresses the types it
  // deems compressible (text/*, application/javascript, ...) with brotli at its highest
  // quality when the browser accepts it, which takes seconds for three.min.js (600 KB).
  // application/x-javascript is one of HTML's JavaScript MIME types and not on that list.
  server.set_file_extension_and_mimetype_mapping("js", "application/x-javascript");
  server.set_file_extension_and_mimetype_mapping("wav", "audio/wav");
  server.set_file_extension_and_mimetype_mapping("bin", "application/octet-stream");
  server.set_default_headers({{"Cache-Control", "no-store"}});
  // SO_REUSEADDR only: httplib's default SO_REUSEPORT would let a second `arco view` bind
  // the same port and share its connections with the first, so that one URL showed
  // either result. Here a busy port is an error.
  server.set_socket_options([](socket_t sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
  });
  const auto refuse = [](const httplib::Request&, httplib::Response& res) { res.status = 405; };
  server.Post(".*", refuse);
  server.Put(".*", refuse);
  server.Delete(".*", refuse);
  server.Patch(".*", refuse);
  const int port = options.port == 0 ? server.bind_to_any_port(options.host)
                   : server.bind_to_port(options.host, options.port) ? options.port
                                                                     : -1;
  if (port < 0) {
    return Status::Error(options.host + ":" + std::to_string(options.port) +
                         ": cannot listen (port in use? --port 0 picks a free one)");
  }

  // SIGINT/SIGTERM go to the watcher (blocked here and in the server's threads, which
  // inherit the mask), which stops the server; the deadline of exit_after_s too.
  sigset_t signals, previous;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, &previous);
  std::atomic<bool> done{false};
  std::thread watcher([&] {
    const auto start = std::chrono::steady_clock::now();
    while (!done) {
      timespec tick = {0, 100 * 1000 * 1000};
      if (sigtimedwait(&signals, nullptr, &tick) > 0) break;
      const double elapsed_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (options.exit_after_s > 0 && elapsed_s >= options.exit_after_s) break;
    }
    server.stop();
  });
  on_listening(port);
  server.listen_after_bind();
  done = true;
  watcher.join();
  pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  return Status::Ok();
}

}  // namespace arco::view
