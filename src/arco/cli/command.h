// Command registry for the `arco` CLI. Each command lives in its own file and
// registers itself with ARCO_REGISTER_COMMAND; the file parses its options
// into a typed struct and calls a library/run function that tests call directly.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "arco/util/path_roles.h"

namespace arco::cli {

// What a command's setup returns: `run` runs it after parsing and returns the process exit
// code (0 ok, 1 error already printed); `paths` (for a command that writes files the user
// names) lists, from the parsed options, every file and folder it reads and writes
// (util/path_roles.h, cli/command_paths.h). The app checks them before `run`: an output
// that is an input, lies inside an input folder or contains one is one error line, and
// nothing is read or written; then the leftovers of interrupted commands beside each
// output go (RemoveStaleTemporaries). docs/architecture.md, "Outputs".
struct CommandRun {
  std::function<int()> run;
  std::function<PathRoles()> paths;

  template <typename F, typename = std::enable_if_t<std::is_invocable_r_v<int, F>>>
  CommandRun(F run_function) : run(std::move(run_function)) {}  // NOLINT: a command's lambda
  CommandRun(std::function<int()> run_function, std::function<PathRoles()> path_function)
      : run(std::move(run_function)), paths(std::move(path_function)) {}
};

// Adds a subcommand to `app` and returns how to run it.
using CommandSetup = std::function<CommandRun(CLI::App& app)>;

// Runs a parsed command: its paths checked (an output is never an input), the stale
// temporaries beside its outputs removed, then `run`.
int RunCommand(const CommandRun& command);

struct CommandEntry {
  std::string name;
  int order;  // position in `arco --help`
  CommandSetup setup;
};

std::vector<CommandEntry>& CommandRegistry();

struct CommandRegistrar {
  CommandRegistrar(std::string name, int order, CommandSetup setup) {
    CommandRegistry().push_back({std::move(name), order, std::move(setup)});
  }
};

// Prints "arco: error: <message>" on stderr; returns 1. After an interrupt (SIGINT,
// SIGTERM: util/interrupt.h) it prints nothing and waits for the cleanup to exit with 130.
int PrintError(const std::string& message);
// Prints "warning: <message>" on stderr: every command's warnings go there, never into
// stdout (which holds the command's results, for scripts and pipes).
void PrintWarning(const std::string& message);
// The exit status of a command that checked something and found problems, as a linter's
// (scripts can act on it): `arco calibrate check` flagging a camera. 1 stays "error".
inline constexpr int kExitFoundProblems = 3;

}  // namespace arco::cli

#define ARCO_REGISTER_COMMAND(name, order, setup) \
  static ::arco::cli::CommandRegistrar arco_registrar_##name(#name, order, setup)
