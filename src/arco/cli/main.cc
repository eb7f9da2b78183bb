// `arco <command> [options]`: the command-line front end. Commands register
// themselves (command.h); this file only dispatches.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <functional>
#include <iostream>
#include <string>

#include "arco/cli/command.h"

namespace arco::cli {

std::vector<CommandEntry>& CommandRegistry() {
  static std::vector<CommandEntry> registry;
  return registry;
}

int PrintError(const std::string& message) {
  std::fprintf(stderr, "arco: error: %s\n", message.c_str());
  return 1;
}

}  // namespace arco::cli

int main(int argc, char** argv) {
  using namespace arco::cli;
  CLI::App app{
      "arco: audio-guided markerless motion capture of string-instrument performance.\n"
      "Run `arco <command> --help` for a command's options (units and defaults)."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "arco 0.1.0");
  auto registry = CommandRegistry();
  std::stable_sort(registry.begin(),
                   registry.end(),
                   [](const CommandEntry& a, const CommandEntry& b) { return a.order < b.order; });
  std::vector<std::pair<CLI::App*, std::function<int()>>> runners;
  for (auto& entry : registry) {
    const size_t before = app.get_subcommands({}).size();
    auto run = entry.setup(app);
    auto subs = app.get_subcommands({});
    if (subs.size() > before) runners.emplace_back(subs.back(), run);
  }
  // CLI11 reports an unknown first word as "A subcommand is required"; name it instead.
  if (argc > 1 && argv[1][0] != '-') {
    std::string known;
    bool found = false;
    for (const auto& [sub, run] : runners) {
      found = found || sub->get_name() == argv[1];
      known += (known.empty() ? "" : ", ") + sub->get_name();
    }
    if (!found) {
      return PrintError("unknown command '" + std::string(argv[1]) + "' (commands: " + known +
                        "; see `arco --help`)");
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() != 0) {
      std::fprintf(stderr, "arco: error: %s\n", e.what());
      return 1;
    }
    return app.exit(e);
  }
  try {
    for (auto& [sub, run] : runners) {
      if (sub->parsed()) return run();
    }
  } catch (const std::exception& e) {
    return PrintError(e.what());
  }
  return PrintError("no command given; see `arco --help`");
}
