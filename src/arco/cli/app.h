// The `arco` command-line app, built the same way for main.cc, the tests and the fuzzer
// (fuzz/cli_args_fuzz.cc): every registered command (command.h) as a subcommand.
//
// Parsing is separate from running: Parse() checks every flag (types, declared ranges,
// cli/number_option.h) and each command's options struct (its Validate(), run by the
// command's parse-complete callback) and throws only CLI::ParseError; nothing is read or
// written until Run().
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "arco/util/status.h"

namespace arco::cli {

struct App {
  std::unique_ptr<CLI::App> app;
  // Each command's subcommand and the function that runs it after a successful parse.
  std::vector<std::pair<CLI::App*, std::function<int()>>> commands;
  // `arco --data-dir DIR`: Run() makes it $ARCO_DATA_DIR (util/data_dir.h). Shared so the
  // option's storage stays put when the App moves.
  std::shared_ptr<std::string> data_dir = std::make_shared<std::string>();
  // `arco --check-args COMMAND ...`: Run() returns 0 after a successful Parse(), running
  // nothing (the workflow checks a take's `options:` so, docs/workflow.md).
  std::shared_ptr<bool> check_args = std::make_shared<bool>(false);

  // Throws CLI::ParseError (CallForHelp and CallForVersion included) and nothing else for
  // any argv. args excludes the program name.
  void Parse(std::vector<std::string> args);
  // The parsed command's exit code (0 ok, 1 error printed). Applies --data-dir first.
  int Run();
};

App BuildApp();

// Ok, or "unknown command 'X' (commands: ...)" for a first word that names no command
// (CLI11 would say "A subcommand is required").
Status CheckCommandName(const App& app, const std::string& first_arg);
// The same for every word that names a command: also the second word of a command made of
// subcommands (`arco capture new`, `arco calibration show`), which must name one of them
// ("unknown command 'capture frob' (capture commands: new, import-keypoints; ...)").
Status CheckCommandNames(const App& app, const std::vector<std::string>& args);

// docs/options.md: every command's options (type, range or choices, default, meaning) as
// the app defines them; app_test.cc checks the page is current (and rewrites it with
// ARCO_WRITE_OPTIONS_DOC=1).
std::string OptionsMarkdown(const App& app);

// `arco ARGS...`: parse, print a parse error or help, run.
int Main(int argc, char** argv);

}  // namespace arco::cli
