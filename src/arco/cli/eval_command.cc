// `arco eval`: scores every method in a result folder against truth and prints
// the ablation table (docs/evaluation.md).
#include <cstdio>
#include <utility>

#include "arco/cli/command.h"
#include "arco/cli/command_paths.h"
#include "arco/cli/flag_names.h"
#include "arco/cli/number_option.h"
#include "arco/eval/evaluate.h"
#include "arco/eval/plot.h"
#include "arco/util/file_io.h"
#include "arco/util/json_io.h"
#include "arco/util/output_set.h"

namespace arco::cli {
namespace {

struct Args {
  eval::EvalRequest r;
  std::vector<std::string> truths;
  std::string output, plot;
};

int Run(Args& a) {
  // One truth without --truth-frame: a synthetic truth folder; else labelled frames.
  if (a.truths.size() == 1 && a.r.truth_frames.empty()) {
    a.r.truth = a.truths[0];
  } else {
    a.r.labels = a.truths;
  }
  // Both outputs declared and checked before the work, written together at the end.
  OutputSet outputs;
  std::string json_tmp, plot_tmp;
  for (auto [path, tmp] : {std::pair{&a.output, &json_tmp}, std::pair{&a.plot, &plot_tmp}}) {
    if (path->empty()) continue;
    auto declared = outputs.AddFile(*path);
    if (!declared.ok()) return PrintError(declared.status().message());
    *tmp = *declared;
  }
  auto report = eval::Evaluate(a.r);
  if (!report.ok()) return PrintError(WithFlagNames(report.status().message(), kEvalFlags));
  Status written = Status::Ok();
  if (!json_tmp.empty()) {
    Json json = report->ToJson(a.r.metrics);
    json["options"] = eval::ToJson(a.r);  // every option used (docs/evaluation.md)
    written = WriteJsonFile(json_tmp, json);
  }
  if (written.ok() && !plot_tmp.empty()) {
    written = AtomicWriteFile(plot_tmp, eval::EvalPlotSvg(*report, report->fps));
  }
  if (written.ok()) written = outputs.Commit();
  if (!written.ok()) return PrintError(written.message());
  std::printf("arco eval: %s truth, %d frames (%d with a pressed note), units %s\n\n",
              report->truth_kind.c_str(),
              report->truth_frames,
              report->contact_frames,
              report->units.c_str());
  std::fputs(report->MarkdownTable(a.r.metrics).c_str(), stdout);
  for (const auto& w : report->warnings)
    std::fprintf(stderr, "arco eval: warning: %s\n", w.c_str());
  if (!a.output.empty()) std::printf("\nwrote %s\n", a.output.c_str());
  if (!a.plot.empty()) std::printf("wrote %s\n", a.plot.c_str());
  return 0;
}

CommandRun SetupEval(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "eval", "Score a result folder against truth (synthetic truth/ or labelled views)");
  auto a = std::make_shared<Args>();
  cmd->add_option("result_dir", a->r.result_dir, "Result folder (result.json with stages)")
      ->required();
  cmd->add_option("--truth",
                  a->truths,
                  "Truth: an `arco synth` truth folder, or points JSONs from `arco triangulate "
                  "--view ...` (repeat, one per labelled frame, each with a --truth-frame)")
      ->required();
  AddNumber(cmd,
            "--truth-frame",
            a->r.truth_frames,
            "Frame number (capture numbering, from 1) each points JSON labels, in order",
            eval::kTruthFrameRange);
  cmd->add_option("--pitch",
                  a->r.pitch_csv,
                  "Estimated pitch.csv (default: RESULT_DIR/pitch.csv when present)");
  AddNumber(cmd,
            "--pck-mm",
            a->r.metrics.pck_thresholds_mm,
            "PCK thresholds (mm)",
            eval::kPckThresholdRangeMm)
      ->capture_default_str();
  AddNumber(cmd,
            "--limit-tolerance-deg",
            a->r.joint_limit_tolerance_deg,
            "Tolerance before a geometric joint angle counts as a limit violation (deg)",
            eval::kJointLimitToleranceRangeDeg)
      ->capture_default_str();
  cmd->add_option("-o,--output", a->output, "Write the metrics as JSON here");
  cmd->add_option(
      "--plot", a->plot, "Write an SVG plot (pitch; hand error and contact deviation per frame)");
  cmd->parse_complete_callback([a] {
    const Status valid = a->r.Validate();
    if (!valid.ok()) throw CLI::ValidationError(WithFlagNames(valid.message(), kEvalFlags));
  });
  return CommandRun([a] { return Run(*a); },
                    [a] {
                      PathRoles roles;
                      AddResultInputs(&roles, "RESULT_DIR", a->r.result_dir);
                      for (const std::string& truth : a->truths) roles.AddInput("--truth", truth);
                      roles.AddInput("--pitch", a->r.pitch_csv);
                      roles.AddOutput("-o", a->output);
                      roles.AddOutput("--plot", a->plot);
                      return roles;
                    });
}

}  // namespace
ARCO_REGISTER_COMMAND(eval, 70, SetupEval);
}  // namespace arco::cli
