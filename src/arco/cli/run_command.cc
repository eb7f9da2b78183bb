// `arco run CAPTURE -o RESULT`: every stage from 2D keypoints and audio to the refined hand
// (pipeline/run_capture.h), with progress per stage and a final summary.
#include <cstdio>
#include <memory>
#include <optional>
#include <utility>

#include "arco/cli/command.h"
#include "arco/cli/command_paths.h"
#include "arco/cli/flag_names.h"
#include "arco/cli/number_option.h"
#include "arco/cli/progress.h"
#include "arco/cli/report.h"
#include "arco/pipeline/run_capture.h"
#include "arco/refine/contact_annotation.h"

namespace arco::cli {
namespace {

struct RunArgs {
  pipeline::RunOptions o;  // bound to the flags: --help shows the library's defaults
  bool average_palm = false;  // o.hands.palm.enabled = !average_palm
  // The capture as opened to list its files (the paths' check before the run), which the
  // run then takes: capture.json is read once. Empty when it did not open: RunCapture
  // opens it again and reports why, in the order of its checks.
  std::optional<pipeline::CaptureContext> opened;
  // The options as validated when the command line was parsed (the run's one validation:
  // RunCapture and its stages take them as they are).
  std::optional<Validated<pipeline::RunOptions>> valid;
};

// The capture folder and the files its manifest names (cli/command_paths.h), from the
// capture opened once (kept in a.opened for the run).
PathRoles RunPaths(RunArgs& a) {
  PathRoles roles;
  StatusOr<pipeline::CaptureContext> opened = pipeline::OpenCapture(a.o.capture_dir);
  if (opened.ok()) {
    AddCaptureInputs(&roles, "CAPTURE", a.o.capture_dir, opened->manifest);
    a.opened = std::move(opened).value();
  } else {
    AddCaptureInputs(&roles, "CAPTURE", a.o.capture_dir);
  }
  roles.AddOutput("-o", a.o.result_dir);
  return roles;
}

int RunRun(RunArgs& a) {
  const pipeline::RunOptions& o = a.o;
  ProgressBar progress;
  StatusOr<pipeline::RunSummary> summary = Status::Error("not run");
  if (a.opened) {
    pipeline::CaptureContext opened = std::move(*a.opened);
    a.opened.reset();
    summary = pipeline::RunCapture(*a.valid, std::move(opened), progress);
  } else {
    summary = pipeline::RunCapture(*a.valid, progress);
  }
  progress.Finish();
  if (!summary.ok()) return PrintError(summary.status().message());
  double total_s = 0;
  for (const pipeline::StageTiming& t : summary->timings) {
    std::printf("%-12s %7.2f s  %s%s\n",
                t.name.c_str(),
                t.seconds,
                FormatStageLine(*summary, t).c_str(),
                t.beside ? " (beside the stages before it)" : "");
    if (!t.beside) total_s += t.seconds;
  }
  for (const auto& m : summary->methods) std::printf("%s\n", FormatRefineSummary(m).c_str());
  for (const std::string& w : summary->warnings) PrintWarning(w);
  // Name only the method folders this run wrote (no audio: vision/ alone).
  std::string folders;
  for (const auto& m : summary->methods) {
    folders += std::string(folders.empty() ? "" : ", ") + refine::RefineModeName(m.mode) + "/";
  }
  std::printf("total %.2f s -> %s (%s: points3d.npy, contacts.csv, fingering.csv)\n",
              total_s,
              o.result_dir.c_str(),
              folders.c_str());
  return 0;
}

CommandRun SetupRun(CLI::App& app) {
  auto* sub = app.add_subcommand(
      "run", "Run every stage on a capture: triangulate, fit hands, pitch, refine, write");
  auto a = std::make_shared<RunArgs>();
  sub->add_option("capture", a->o.capture_dir, "Capture folder (capture.json, docs/formats.md)")
      ->required();
  sub->add_option("-o,--output", a->o.result_dir, "Result folder to write")->required();
  sub->add_flag("--overwrite", a->o.overwrite, "Replace an existing result folder");
  sub->add_flag("--average-palm",
                a->average_palm,
                "Fit the hand with the average hand's palm instead of the performer's, estimated "
                "from the take (docs/hand.md)");
  sub->add_flag("--double-stops",
                a->o.double_stops,
                "Double stops: track two simultaneous notes and give arco a second string, "
                "finger and contact per frame (arco/contacts_2.csv; docs/refine.md)");
  AddNumber(sub,
            "--threads",
            a->o.num_threads,
            "Worker threads (0 = all cores; results do not depend on it)",
            kThreadsRange)
      ->capture_default_str();
  AddNumber(sub,
            "--min-confidence",
            a->o.refine.pitch.min_confidence,
            "Pitch confidence below which a frame gets no contact",
            kMinConfidenceRange)
      ->capture_default_str();
  sub->parse_complete_callback([a] {
    a->o.hands.palm.enabled = !a->average_palm;
    StatusOr<Validated<pipeline::RunOptions>> valid = Validated<pipeline::RunOptions>::Check(a->o);
    if (!valid.ok()) {
      ThrowIfInvalid(Status::Error(WithFlagNames(valid.status().message(), kRefineFlags)));
    }
    a->valid = std::move(valid).value();
  });
  return CommandRun([a]() { return RunRun(*a); }, [a] { return RunPaths(*a); });
}

}  // namespace
ARCO_REGISTER_COMMAND(run, 50, SetupRun);
}  // namespace arco::cli
