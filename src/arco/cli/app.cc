#include "arco/cli/app.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>

#include "arco/cli/build_info.h"
#include "arco/cli/command.h"
#include "arco/cli/manual.h"
#include "arco/util/data_dir.h"
#include "arco/util/interrupt.h"
#include "arco/util/output_set.h"

namespace arco::cli {

std::vector<CommandEntry>& CommandRegistry() {
  static std::vector<CommandEntry> registry;
  return registry;
}

void PrintWarning(const std::string& message) {
  std::fprintf(stderr, "warning: %s\n", message.c_str());
}

int PrintError(const std::string& message) {
  WaitIfInterrupted();  // an error caused by the cleanup removing a temporary is not news
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
  app.set_version_flag("--version", VersionLine(), "Print the version and the source revision");
  app.add_option("--data-dir",
                 *built.data_dir,
                 "Folder of arco's data (viewer page, three.js, detector models, workflow); "
                 "default: $ARCO_DATA_DIR, else ../share/arco beside the executable's folder");
  app.add_flag("--check-args",
               *built.check_args,
               "Check the command line (every flag and range, the command's options) and exit "
               "0 when it is valid, reading and writing nothing");
  auto registry = CommandRegistry();
  std::stable_sort(registry.begin(),
                   registry.end(),
                   [](const CommandEntry& a, const CommandEntry& b) { return a.order < b.order; });
  for (auto& entry : registry) {
    const size_t before = app.get_subcommands({}).size();
    CommandRun command = entry.setup(app);
    auto subs = app.get_subcommands({});
    if (subs.size() > before) {
      built.commands.emplace_back(subs.back(), [command] { return RunCommand(command); });
    }
  }
  return built;
}

int RunCommand(const CommandRun& command) {
  if (command.paths) {
    const PathRoles roles = command.paths();
    const Status distinct = roles.Check();
    if (!distinct.ok()) return PrintError(distinct.message());
    for (const std::string& output : roles.output_paths()) RemoveStaleTemporaries(output);
  }
  return command.run();
}

void App::Parse(std::vector<std::string> args) {
  std::reverse(args.begin(), args.end());  // CLI11 takes them last first
  app->parse(args);
}

int App::Run() {
  if (*check_args) return 0;  // Parse() has checked everything a command line can hold
  // --data-dir as $ARCO_DATA_DIR, which every lookup (util/data_dir.h) and every arco this
  // one starts (arco batch's workflow) reads.
  if (!data_dir->empty()) {
    std::error_code ec;
    if (!std::filesystem::is_directory(*data_dir, ec)) {
      return PrintError(*data_dir + ": no such folder (--data-dir)");
    }
    setenv(kDataDirEnv, data_dir->c_str(), 1);
  }
  // `arco batch` finds its Snakefile through $ARCO_WORKFLOW_DIR: the data folder's.
  const std::string data = DataDir();
  const char* workflow = std::getenv("ARCO_WORKFLOW_DIR");
  if (!data.empty() && (workflow == nullptr || *workflow == '\0')) {
    setenv("ARCO_WORKFLOW_DIR", (std::filesystem::path(data) / "workflow").c_str(), 1);
  }
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

Status CheckCommandNames(const App& app, const std::vector<std::string>& args) {
  if (args.empty()) return Status::Ok();
  ARCO_RETURN_IF_ERROR(CheckCommandName(app, args[0]));
  const CLI::App* command = nullptr;
  for (const auto& [sub, run] : app.commands) {
    if (sub->get_name() == args[0]) command = sub;
  }
  if (!command || command->get_subcommands({}).empty() ||
      command->get_require_subcommand_min() == 0) {
    return Status::Ok();
  }
  std::string known;
  bool found = false;
  for (const CLI::App* sub : command->get_subcommands({})) {
    found = found || (args.size() > 1 && sub->get_name() == args[1]);
    known += (known.empty() ? "" : ", ") + sub->get_name();
  }
  const std::string help = "see `arco " + args[0] + " --help`";
  if (args.size() == 1) {
    return Status::Error("'" + args[0] + "' needs a command (" + known + "; " + help + ")");
  }
  if (found || args[1].empty() || args[1][0] == '-') return Status::Ok();
  return Status::Error("unknown command '" + args[0] + " " + args[1] + "' (" + args[0] +
                       " commands: " + known + "; " + help + ")");
}

namespace {

std::string Escape(std::string text) {
  for (size_t at = text.find('|'); at != std::string::npos; at = text.find('|', at + 2)) {
    text.replace(at, 1, "\\|");
  }
  return text;
}

void AppendCommand(const CLI::App& command, const std::string& path, std::string* out) {
  std::string rows;
  for (const OptionDoc& o : DocumentedOptions(command)) {
    std::string names;
    for (const std::string& name : o.names) names += (names.empty() ? "`" : ", `") + name + "`";
    rows += "| " + names + " | " + o.type + (o.required ? ", required" : "") + " | " +
            Escape(o.check) + " | " + Escape(o.default_value) + " | " + Escape(o.description) +
            " |\n";
  }
  if (!rows.empty()) {
    *out += "\n## arco " + path + "\n\n" + Escape(command.get_description()) +
            "\n\n| option | type | range / choices | default | meaning |\n|---|---|---|---|---|\n" +
            rows;
  }
  for (const CLI::App* sub : command.get_subcommands({})) {
    AppendCommand(*sub, path + " " + sub->get_name(), out);
  }
}

}  // namespace

std::string OptionsMarkdown(const App& app) {
  std::string out =
      "# Command-line options\n\n"
      "Every option of every command with the values it accepts, generated from the commands'\n"
      "own definitions (cli/app.h OptionsMarkdown; `cli_app_test` fails when this page is out\n"
      "of date, and `ARCO_WRITE_OPTIONS_DOC=1 build/tests/cli_app_test` rewrites it).\n\n"
      "A number outside its range, NaN, an infinity, a value that would wrap (`--seed -1`)\n"
      "or text where a number belongs is rejected before any work with one line naming the\n"
      "flag, the value and the range (`arco: error: --fps: nan is not a finite number in\n"
      "(0, 1000]`), exit status 1, nothing written. `[a, b]` includes both ends, `(a, b]`\n"
      "excludes a. `arco <command> --help` shows the same ranges after the type\n"
      "(`FLOAT:(0, 1000]`). The options applied are recorded with the results: result.json\n"
      "\"options\" (`arco run`) and each method's \"options\" (`arco run`, `arco refine`),\n"
      "eval.json \"options\" (`arco eval`); docs/formats.md.\n";
  for (const auto& [sub, run] : app.commands) AppendCommand(*sub, sub->get_name(), &out);
  return out;
}

int Main(int argc, char** argv) {
  InstallInterruptCleanup();  // Ctrl-C removes what is being written, exit 130
  App app = BuildApp();
  if (argc > 1) {
    const Status known = CheckCommandNames(app, std::vector<std::string>(argv + 1, argv + argc));
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
  const int status = app.Run();
  WaitIfInterrupted();  // the cleanup thread sets the exit status (130)
  return status;
}

}  // namespace arco::cli
