// Command registry for the `arco` CLI. Each command lives in its own file and
// registers itself with ARCO_REGISTER_COMMAND; the file parses its options
// into a typed struct and calls a library/run function that tests call directly.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace arco::cli {

// Adds a subcommand to `app`; the returned callback runs it after parsing and
// returns the process exit code (0 ok, 1 error already printed).
using CommandSetup = std::function<std::function<int()>(CLI::App& app)>;

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

// Prints "arco: error: <message>" on stderr; returns 1.
int PrintError(const std::string& message);

}  // namespace arco::cli

#define ARCO_REGISTER_COMMAND(name, order, setup) \
  static ::arco::cli::CommandRegistrar arco_registrar_##name(#name, order, setup)
