// `arco batch TAKES -o OUT`: the datasets workflow (workflow/Snakefile, docs/workflow.md)
// for people who do not know Snakemake. It builds the snakemake command line and replaces
// this process with it, so Snakemake's output, exit status and Ctrl-C are the user's.
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "arco/cli/command.h"
#include "arco/cli/number_option.h"

namespace arco::cli {
namespace {

namespace fs = std::filesystem;

struct BatchOptions {
  std::string takes_dir;
  std::string output_dir;
  int cores = 0;  // 0 = all cores
  bool keep_going = false;
  bool dry_run = false;
  bool print_command = false;
  std::string profile;                  // Snakemake profile (cluster); --cores only when given
  std::string workflow;                 // folder holding the Snakefile
  std::string snakemake = "snakemake";  // executable, found on PATH
};

// The Snakefile's folder: --workflow, else $ARCO_WORKFLOW_DIR, else the source tree's.
std::string WorkflowDir(const BatchOptions& o) {
  if (!o.workflow.empty()) return o.workflow;
  if (const char* env = std::getenv("ARCO_WORKFLOW_DIR"); env != nullptr && *env != '\0') {
    return env;
  }
  return ARCO_WORKFLOW_DIR;
}

std::string Absolute(const std::string& path) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(path, ec);
  return ec ? path : absolute.lexically_normal().string();
}

// This executable, so that the workflow runs the same arco.
std::string SelfPath() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? "arco" : self.string();
}

std::vector<std::string> SnakemakeArgs(const BatchOptions& o, const std::string& workflow_dir) {
  std::vector<std::string> args = {o.snakemake, "-s", workflow_dir + "/Snakefile"};
  if (!o.profile.empty()) {
    args.insert(args.end(), {"--profile", Absolute(o.profile)});
  }
  if (o.profile.empty() || o.cores > 0) {
    const unsigned all = std::max(1u, std::thread::hardware_concurrency());
    args.insert(args.end(), {"--cores", std::to_string(o.cores > 0 ? o.cores : all)});
  }
  if (o.keep_going) args.push_back("--keep-going");
  if (o.dry_run) args.push_back("--dry-run");
  args.insert(args.end(),
              {"--config",
               "takes=" + Absolute(o.takes_dir),
               "out=" + Absolute(o.output_dir),
               "arco=" + SelfPath()});
  return args;
}

std::string ShellQuote(const std::string& word) {
  if (word.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                             "_-./=,:+@") == std::string::npos) {
    return word;
  }
  std::string quoted = "'";
  for (char c : word) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

int RunBatch(const BatchOptions& o) {
  std::error_code ec;
  if (!fs::is_directory(o.takes_dir, ec)) {
    return PrintError(o.takes_dir + ": no such folder of takes");
  }
  const std::string workflow_dir = WorkflowDir(o);
  if (!fs::is_regular_file(workflow_dir + "/Snakefile", ec)) {
    return PrintError(workflow_dir +
                      "/Snakefile: not found; give the repository's workflow/ folder with "
                      "--workflow or $ARCO_WORKFLOW_DIR");
  }
  if (!o.profile.empty() && !fs::is_regular_file(o.profile + "/config.yaml", ec)) {
    return PrintError(o.profile +
                      "/config.yaml: not found; --profile takes a Snakemake "
                      "profile folder such as workflow/profiles/slurm");
  }
  const std::vector<std::string> args = SnakemakeArgs(o, workflow_dir);
  if (o.print_command) {
    std::string line;
    for (const std::string& word : args) line += (line.empty() ? "" : " ") + ShellQuote(word);
    std::printf("%s\n", line.c_str());
    return 0;
  }
  std::vector<char*> argv;
  for (const std::string& word : args) argv.push_back(const_cast<char*>(word.c_str()));
  argv.push_back(nullptr);
  std::fflush(stdout);
  execvp(argv[0], argv.data());
  const int error = errno;  // execvp returns only on failure
  if (error == ENOENT) {
    return PrintError(o.snakemake +
                      ": not found; arco batch runs the workflow with Snakemake 7 (Debian: "
                      "apt-get install snakemake, or scripts/setup)");
  }
  return PrintError(o.snakemake + ": cannot run: " + std::strerror(error));
}

CommandRun SetupBatch(CLI::App& app) {
  auto o = std::make_shared<BatchOptions>();
  auto* cmd = app.add_subcommand(
      "batch",
      "Run every take of a folder (capture folders, video sessions with take.yaml, SPD "
      "sessions) through the Snakemake workflow, with a summary table (docs/workflow.md)");
  cmd->add_option("takes", o->takes_dir, "Folder of takes, one sub-folder per take")->required();
  cmd->add_option("-o,--output", o->output_dir, "Folder for every take's outputs and the summary")
      ->required();
  AddNumber(cmd, "--cores", o->cores, "Cores to use at once (0 = all)", kThreadsRange)
      ->capture_default_str();
  cmd->add_flag("--keep-going", o->keep_going, "Finish the other takes when one fails");
  cmd->add_flag("-n,--dry-run", o->dry_run, "List the jobs that would run; run nothing");
  cmd->add_option("--profile",
                  o->profile,
                  "Snakemake profile folder for a cluster (workflow/profiles/slurm, "
                  "workflow/profiles/cluster)");
  cmd->add_flag("--print-command", o->print_command, "Print the snakemake command; run nothing");
  cmd->add_option("--workflow",
                  o->workflow,
                  "Folder of the Snakefile (default: $ARCO_WORKFLOW_DIR, else the source "
                  "tree's workflow/)");
  cmd->add_option("--snakemake", o->snakemake, "Snakemake executable")->capture_default_str();
  return CommandRun([o] { return RunBatch(*o); },
                    [o] {
                      PathRoles roles;
                      roles.AddInput("TAKES", o->takes_dir);
                      roles.AddOutput("-o", o->output_dir);
                      return roles;
                    });
}

}  // namespace
ARCO_REGISTER_COMMAND(batch, 75, SetupBatch);
}  // namespace arco::cli
