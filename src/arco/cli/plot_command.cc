// `arco plot`: a result's figures as SVG and PNG (docs/export.md, "Plots").
#include <cstdio>

#include "arco/cli/command.h"
#include "arco/cli/command_paths.h"
#include "arco/cli/flag_names.h"
#include "arco/cli/number_option.h"
#include "arco/export/plot.h"
#include "arco/util/output_set.h"

namespace arco::cli {
namespace {

inline constexpr FieldFlag kPlotFlags[] = {{"result_dir", "RESULT_DIR"},
                                           {"method", "--method"},
                                           {"width", "--width"},
                                           {"height", "--height"}};
inline constexpr NumberRange kPlotWidthRange = Closed(400, 8000);
inline constexpr NumberRange kPlotHeightRange = Closed(300, 8000);

struct Args {
  exporter::PlotOptions options;
  std::string output;
  bool overwrite = false;
};

int Run(const Args& a) {
  OutputSet outputs;
  FolderReplace replace;
  replace.overwrite = a.overwrite;
  replace.marker = "pitch.svg";  // only a folder of arco plot's is ever replaced
  replace.kind = "plot folder";
  auto tmp = outputs.AddFolder(a.output, replace);
  if (!tmp.ok()) return PrintError(tmp.status().message());
  auto summary = exporter::WritePlots(a.options, *tmp);
  if (!summary.ok()) return PrintError(WithFlagNames(summary.status().message(), kPlotFlags));
  const Status committed = outputs.Commit();
  if (!committed.ok()) return PrintError(committed.message());
  std::string files;
  for (const auto& f : summary->files) files += (files.empty() ? "" : " ") + f;
  std::printf("arco plot: method %s, %d notes%s -> %s/ (%s)\n",
              a.options.method.c_str(),
              summary->notes,
              summary->errors ? ", errors against the truth" : "",
              a.output.c_str(),
              files.c_str());
  return 0;
}

CommandRun SetupPlot(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "plot", "Plot a result: pitch and notes, the fingerboard map, errors (SVG and PNG)");
  auto a = std::make_shared<Args>();
  cmd->add_option("result_dir", a->options.result_dir, "Result folder (from arco run)")->required();
  cmd->add_option("--method", a->options.method, "Whose fingering: arco or paper")
      ->capture_default_str();
  AddNumber(cmd, "--width", a->options.width, "Figure width (px)", kPlotWidthRange)
      ->capture_default_str();
  AddNumber(cmd, "--height", a->options.height, "Figure height (px)", kPlotHeightRange)
      ->capture_default_str();
  cmd->add_option("-o,--output", a->output, "Output folder (created)")->required();
  cmd->add_flag("--overwrite", a->overwrite, "Replace an earlier arco plot folder");
  cmd->parse_complete_callback([a] {
    const Status valid = a->options.Validate();
    if (!valid.ok()) throw CLI::ValidationError(WithFlagNames(valid.message(), kPlotFlags));
  });
  return CommandRun([a] { return Run(*a); },
                    [a] {
                      PathRoles roles;
                      AddResultInputs(&roles, "RESULT_DIR", a->options.result_dir);
                      roles.AddOutput("-o", a->output);
                      return roles;
                    });
}

}  // namespace
ARCO_REGISTER_COMMAND(plot, 77, SetupPlot);
}  // namespace arco::cli
