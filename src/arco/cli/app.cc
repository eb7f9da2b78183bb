#include "arco/cli/app.h"

#include <algorithm>
#include <cstdio>
#include <exception>

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

App BuildApp() {
  App built;
  built.app = std::make_unique<CLI::App>(
      "arco: audio-guided markerless motion capture of string-instrument performance.\n"
      "Run `arco <command> --help` for a command's options (units, ranges and defaults).");
  CLI::App& app = *built.app;
  app.require_subcommand(1);
  app.set_version_flag("--version", "arco 0.1.0");
  auto registry = CommandRegistry();
  std::stable_sort(registry.begin(),
                   registry.end(),
                   [](const CommandEntry& a, const CommandEntry& b) { return a.order < b.order; });
  for (auto& entry : registry) {
    const size_t before = app.get_subcommands({}).size();
    auto run = entry.setup(app);
    auto subs = app.get_subcommands({});
    if (subs.size() > before) built.commands.emplace_back(subs.back(), run);
  }
  return built;
}

void App::Parse(std::vector<std::string> args) {
  std::reverse(args.begin(), args.end());  // CLI11 takes them last first
  app->parse(args);
}

int App::Run() {
  try {
    for (auto& [sub, run] : commands) {
      if (sub->parsed()) return run();
    }
  } catch (const std::exception& e) {
    return PrintError(e.what());
  }
  return PrintError("no command given; see `arco --help`");
}

Status CheckCommandName(const App& app, const std::string& first_arg) {
  if (first_arg.empty() || first_arg[0] == '-') return Status::Ok();
  std::string known;
  bool found = false;
  for (const auto& [sub, run] : app.commands) {
    found = found || sub->get_name() == first_arg;
    known += (known.empty() ? "" : ", ") + sub->get_name();
  }
  if (found) return Status::Ok();
  return Status::Error("unknown command '" + first_arg + "' (commands: " + known +
                       "; see `arco --help`)");
}

int Main(int argc, char** argv) {
  App app = BuildApp();
  if (argc > 1) {
    const Status known = CheckCommandName(app, argv[1]);
    if (!known.ok()) return PrintError(known.message());
  }
  try {
    app.Parse(std::vector<std::string>(argv + 1, argv + argc));
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() != 0) return PrintError(e.what());
    return app.app->exit(e);
  } catch (const std::exception& e) {  // a bug (the fuzzer looks for these): one line still
    return PrintError(e.what());
  }
  return app.Run();
}

}  // namespace arco::cli
