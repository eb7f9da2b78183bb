// `arco run CAPTURE -o RESULT`: every stage from 2D keypoints and audio to the refined hand
// (pipeline/run_capture.h), with progress per stage and a final summary.
#include <cstdio>
#include <memory>

#include "arco/cli/command.h"
#include "arco/cli/progress.h"
#include "arco/cli/report.h"
#include "arco/pipeline/run_capture.h"
#include "arco/refine/contact_annotation.h"

namespace arco::cli {
namespace {

struct RunArgs {
  std::string capture, output;
  int threads = 0;
  double min_confidence = 0.5;
  bool overwrite = false;
};

int RunRun(const RunArgs& a) {
  pipeline::RunOptions o;
  o.capture_dir = a.capture;
  o.result_dir = a.output;
  o.num_threads = a.threads;
  o.overwrite = a.overwrite;
  o.refine.pitch.min_confidence = a.min_confidence;
  ProgressBar progress;
  auto summary = pipeline::RunCapture(o, progress);
  progress.Finish();
  if (!summary.ok()) return PrintError(summary.status().message());
  double total_s = 0;
  for (const pipeline::StageTiming& t : summary->timings) {
    std::printf(
        "%-12s %7.2f s  %s\n", t.name.c_str(), t.seconds, FormatStageLine(*summary, t).c_str());
    total_s += t.seconds;
  }
  for (const auto& m : summary->methods) std::printf("%s\n", FormatRefineSummary(m).c_str());
  for (const std::string& w : summary->warnings) std::printf("warning: %s\n", w.c_str());
  // Name only the method folders this run wrote (no audio: vision/ alone).
  std::string folders;
  for (const auto& m : summary->methods) {
    folders += std::string(folders.empty() ? "" : ", ") + refine::RefineModeName(m.mode) + "/";
  }
  std::printf("total %.2f s -> %s (%s: points3d.npy, contacts.csv, fingering.csv)\n",
              total_s,
              a.output.c_str(),
              folders.c_str());
  return 0;
}

std::function<int()> SetupRun(CLI::App& app) {
  auto* sub = app.add_subcommand(
      "run", "Run every stage on a capture: triangulate, fit hands, pitch, refine, write");
  auto a = std::make_shared<RunArgs>();
  sub->add_option("capture", a->capture, "Capture folder (capture.json, docs/formats.md)")
      ->required();
  sub->add_option("-o,--output", a->output, "Result folder to write")->required();
  sub->add_flag("--overwrite", a->overwrite, "Replace an existing result folder");
  sub->add_option(
         "--threads", a->threads, "Worker threads (0 = all cores; results do not depend on it)")
      ->default_val(0);
  sub->add_option("--min-confidence",
                  a->min_confidence,
                  "Pitch confidence below which a frame gets no contact (0-1)")
      ->default_val(0.5);
  return [a]() { return RunRun(*a); };
}

}  // namespace
ARCO_REGISTER_COMMAND(run, 50, SetupRun);
}  // namespace arco::cli
