// The local server of `arco view`: a GET-only static server of one folder on 127.0.0.1
// (cpp-httplib), so that the page can fetch() its binary arrays.
#pragma once

#include <functional>
#include <string>

#include "arco/util/status.h"

namespace arco::view {

struct ServeOptions {
  std::string dir;  // the folder served at "/"
  std::string host = "127.0.0.1";
  int port = 8765;          // 0: any free port
  double exit_after_s = 0;  // > 0: stop after this long (tests); 0: until SIGINT/SIGTERM
  Status Validate() const;
};

// Blocks until SIGINT or SIGTERM (or exit_after_s); `on_listening(port)` is called once the
// socket is bound. SIGINT and SIGTERM are blocked in the calling thread while it serves
// and waited for by a watcher thread, so that Ctrl-C stops the server cleanly and the
// caller can remove its folder. Errors: the port cannot be bound.
Status ServeFolder(const ServeOptions& options, const std::function<void(int port)>& on_listening);

}  // namespace arco::view
