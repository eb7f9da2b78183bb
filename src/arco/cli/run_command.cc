// `arco run CAPTURE -o RESULT`: every stage from 2D keypoints and audio to the refined hand
// (run.h), with progress per stage and a final summary.
#include <cstdio>
#include <memory>

#include "arco/cli/command.h"
#include "arco/cli/progress.h"
#include "arco/cli/run.h"

namespace arco::cli {
namespace {

struct RunArgs {
  std::string capture, output;
  int threads = 0;
  double min_confidence = 0.5;
};

int RunRun(const RunArgs& a) {
  RunOptions o;
  o.capture_dir = a.capture;
  o.result_dir = a.output;
  o.num_threads = a.threads;
  o.refine.pitch.min_confidence = a.min_confidence;
  std::unique_ptr<ProgressBar> bar;
  std::string stage_name;
  RunProgress progress;
  progress.on_stage = [&](int index, int count, const std::string& name) {
    if (bar) bar->Finish();
    bar.reset();
    stage_name = name;
    std::fprintf(stderr, "[%d/%d] %s\n", index, count, name.c_str());
  };
  progress.on_total = [&](int64_t total) {
    bar = std::make_unique<ProgressBar>(stage_name, total);
  };
  progress.on_advance = [&](int64_t done) {
    if (bar) bar->Add(done);
  };
  auto summary = RunCapture(o, progress);
  if (bar) bar->Finish();
  if (!summary.ok()) return PrintError(summary.status().message());
  double total_s = 0;
  for (const StageReport& s : summary->stages) {
    std::printf("%-12s %7.2f s  %s\n", s.name.c_str(), s.seconds, s.summary.c_str());
    total_s += s.seconds;
  }
  for (const auto& m : summary->methods) std::printf("%s\n", FormatRefineSummary(m).c_str());
  for (const std::string& w : summary->warnings) std::printf("warning: %s\n", w.c_str());
  std::printf(
      "total %.2f s -> %s (vision/, paper/, arco/: points3d.npy, contacts.csv, "
      "fingering.csv)\n",
      total_s,
      a.output.c_str());
  return 0;
}

std::function<int()> SetupRun(CLI::App& app) {
  auto* sub = app.add_subcommand(
      "run", "Run every stage on a capture: triangulate, fit hands, pitch, refine, write");
  auto a = std::make_shared<RunArgs>();
  sub->add_option("capture", a->capture, "Capture folder (capture.json, docs/formats.md)")
      ->required();
  sub->add_option("-o,--output", a->output, "Result folder to write")->required();
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
