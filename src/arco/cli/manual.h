// The `arco` manual, generated from the commands' own definitions (BuildApp, the same
// source as docs/options.md), so it never disagrees with `--help`: the man pages arco(1)
// and arco-COMMAND(1) (arco-capture-new(1) for a command's subcommand), and the bash
// completion. `arco_manual` (manual_main.cc) writes them at build time; `cmake --install`
// installs them (docs/install.md).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "arco/cli/app.h"

namespace arco::cli {

// One option of a command as --help shows it.
struct OptionDoc {
  std::vector<std::string> names;  // "-o", "--output"; a positional argument's one name
  bool positional = false;
  std::string type;  // "FLOAT", "INT", "TEXT", ...; "flag" for an option without a value
  bool required = false;
  std::string check;                 // the declared range or choices: "[0, 1000]", "{none,cello}"
  std::vector<std::string> choices;  // the choices of a "{a,b}" check, else empty
  std::string default_value;         // "" when none is shown
  std::string description;
};

// A command's options and positional arguments in their declaration order, --help left out.
std::vector<OptionDoc> DocumentedOptions(const CLI::App& command);

struct ManPage {
  std::string name;  // "arco", "arco-run", "arco-capture-new": the file is NAME.1
  std::string text;  // roff (man(7) macros)
};

// arco(1) and one page per command and subcommand, in `arco --help`'s order.
std::vector<ManPage> ManPages(const App& app);

// A bash completion script (`complete -F _arco arco`): command and subcommand names,
// each command's options, the choices of options that declare them, file names elsewhere.
std::string BashCompletion(const App& app);

}  // namespace arco::cli
