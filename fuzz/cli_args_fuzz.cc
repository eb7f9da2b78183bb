// `arco ARGS...` parsing: the input's bytes split on NUL and newline are the arguments.
// The app is built as `arco` builds it (cli/app.h) and only parsed and validated, never
// run: any argv must end in success or a CLI::ParseError (help, version, a bad value, an
// unknown option or command), never in a crash, a hang or another exception.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "arco/cli/app.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  constexpr size_t kMaxArgs = 64;  // more says nothing new and slows every run
  std::vector<std::string> args(1);
  for (size_t i = 0; i < size && args.size() <= kMaxArgs; ++i) {
    const char c = static_cast<char>(data[i]);
    if (c == '\0' || c == '\n') {
      args.emplace_back();
    } else {
      args.back().push_back(c);
    }
  }
  if (args.size() > kMaxArgs) args.resize(kMaxArgs);
  arco::cli::App app = arco::cli::BuildApp();
  (void)arco::cli::CheckCommandName(app, args.front());  // a Status, never throws
  (void)arco::cli::CheckCommandNames(app, args);
  try {
    app.Parse(args);
  } catch (const CLI::ParseError&) {
    // The expected outcome for most inputs.
  }
  return 0;
}
