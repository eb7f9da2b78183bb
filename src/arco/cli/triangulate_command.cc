// `arco triangulate`: 3D points from labelled views, or whole captures.
#include <chrono>
#include <cstdio>
#include <memory>

#include "arco/capture/label_views.h"
#include "arco/cli/command.h"
#include "arco/cli/command_paths.h"
#include "arco/cli/number_option.h"
#include "arco/cli/progress.h"
#include "arco/cli/report.h"
#include "arco/instrument/instrument_model.h"
#include "arco/pipeline/triangulate_stage.h"
#include "arco/util/output_set.h"

namespace arco::cli {
namespace {

struct Args {
  std::string capture_dir, output, calibration, label_origin = "corner", scale_instrument;
  std::vector<std::string> views, filters;
  TriangulationOptions t;
  bool no_refine = false, ignore_distortion = false;
  int threads = 0, max_gap_frames = 5;
};

// "KEY=VALUE" -> (KEY, VALUE); `form` is shown in the error, e.g. "CAMERA=LABELME.json".
StatusOr<std::pair<std::string, std::string>> SplitAssignment(const std::string& s,
                                                              const std::string& option,
                                                              const std::string& form) {
  const size_t eq = s.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == s.size()) {
    return Status::Error(option + " \"" + s + "\" must look like " + form);
  }
  return std::make_pair(s.substr(0, eq), s.substr(eq + 1));
}

int RunViews(const Args& a) {
  capture::LabelViewsOptions o;
  o.calibration = a.calibration;
  o.triangulation = a.t;
  o.ignore_distortion = a.ignore_distortion;
  o.label_origin = a.label_origin == "center" ? PixelOrigin::kCenter : PixelOrigin::kCorner;
  for (const auto& v : a.views) {
    auto kv = SplitAssignment(v, "--view", "CAMERA=LABELME.json");
    if (!kv.ok()) return PrintError(kv.status().message());
    o.views.push_back(*kv);
  }
  if (!a.scale_instrument.empty()) {
    auto model = InstrumentModel::Create(a.scale_instrument);
    if (!model.ok()) return PrintError("--scale-to: " + model.status().message());
    o.reference_string_length_mm = model->string_length_mm();
  }
  const Status writable = CheckOutputFile(a.output);  // before the work
  if (!writable.ok()) return PrintError(writable.message());
  auto result = capture::TriangulateLabelViews(o);
  if (!result.ok()) return PrintError(result.status().message());
  const Status written = WriteJsonFile(a.output, *result);
  if (!written.ok()) return PrintError(written.message());
  std::fputs(FormatLabelViewsReport(*result).c_str(), stdout);
  std::printf("wrote %s\n", a.output.c_str());
  return 0;
}

int RunCaptureFolder(const Args& a) {
  pipeline::TriangulateStageOptions o;
  o.capture_dir = a.capture_dir;
  o.result_dir = a.output;
  o.triangulation.point = a.t;
  o.triangulation.num_threads = a.threads;
  for (const auto& f : a.filters) {
    auto kv = SplitAssignment(f, "--filter", "GROUP=SPEC");
    if (!kv.ok()) return PrintError(kv.status().message());
    auto spec = ParseFilterSpec(kv->second);
    if (!spec.ok()) return PrintError("--filter " + f + ": " + spec.status().message());
    spec->max_gap_frames = a.max_gap_frames;
    o.filters.emplace_back(kv->first, *spec);
  }
  ProgressBar bar("triangulate");
  const auto start = std::chrono::steady_clock::now();
  auto summary = pipeline::RunTriangulateStage(o, bar);
  bar.Finish();
  if (!summary.ok()) return PrintError(summary.status().message());
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto& s = summary->triangulation;
  std::printf(
      "triangulated %lld of %lld points (%.1f%%) over %lld frames x %lld keypoints from %lld "
      "views\nmedian reprojection RMS %.2f px, mean inlier views %.1f, units %s\n"
      "time %.2f s (%.0f points/s) -> %s\n",
      static_cast<long long>(s.triangulated),
      static_cast<long long>(s.points),
      s.points ? 100.0 * s.triangulated / s.points : 0.0,
      static_cast<long long>(s.frames),
      static_cast<long long>(summary->keypoints),
      static_cast<long long>(summary->views),
      s.median_rms_reprojection_px,
      s.mean_inliers,
      summary->units.c_str(),
      seconds,
      seconds > 0 ? s.points / seconds : 0.0,
      a.output.c_str());
  if (!summary->removed_stages.empty()) {
    // They were made from the triangulation just replaced (docs/architecture.md).
    std::string names;
    for (const std::string& n : summary->removed_stages) names += (names.empty() ? "" : ", ") + n;
    std::printf(
        "removed the later stages made from the old triangulation: %s (arco run redoes "
        "them)\n",
        names.c_str());
  }
  return 0;
}

CommandRun Setup(CLI::App& app) {
  auto a = std::make_shared<Args>();
  CLI::App* sub = app.add_subcommand(
      "triangulate",
      "3D keypoints from calibrated views: labelled views (--calibration, --view) to a JSON "
      "file, or a capture folder (docs/formats.md) to a result folder");
  sub->add_option("capture_dir",
                  a->capture_dir,
                  "Capture folder with capture.json and 2D keypoints (sequence mode)");
  sub->add_option(
         "-o,--output", a->output, "Output: JSON file (labelled views) or result folder (capture)")
      ->required();
  sub->add_option("--calibration",
                  a->calibration,
                  "Calibration file (Metashape XML, SPD JSON, OpenCV YAML/XML, arco JSON)");
  sub->add_option(
      "--view", a->views, "CAMERA=LABELME.json, CAMERA a camera name or serial; repeat per view");
  AddNumber(sub, "--min-score", a->t.min_score, "Ignore detections below this score", kFractionRange)
      ->capture_default_str();
  AddNumber(sub,
            "--max-reprojection-px",
            a->t.max_reprojection_px,
            "RANSAC inlier gate, pixels",
            AboveZero(10000))
      ->capture_default_str();
  AddNumber(sub,
            "--max-ransac-trials",
            a->t.max_ransac_trials,
            "Most camera pairs tried per point (all pairs when fewer)",
            Closed(1, 1000000))
      ->capture_default_str();
  AddNumber(sub,
            "--robust-loss-px",
            a->t.robust_loss_scale_px,
            "Soft-L1 loss scale of the refinement, pixels",
            AboveZero(10000))
      ->capture_default_str();
  sub->add_flag("--no-refine", a->no_refine, "Skip the Levenberg-Marquardt refinement");
  sub->add_flag("--ignore-distortion",
                a->ignore_distortion,
                "Triangulate as if the lenses had no distortion (for comparison)");
  sub->add_option("--label-origin",
                  a->label_origin,
                  "Pixel origin of labelme coordinates: corner (labelme) or center (OpenCV)")
      ->check(CLI::IsMember({"corner", "center"}))
      ->capture_default_str();
  sub->add_option("--scale-to",
                  a->scale_instrument,
                  "Also report lengths in mm, taking the mean string side (nut-bridge) as this "
                  "instrument's string length (cello 695 mm, violin 328 mm)");
  AddNumber(sub,
            "--threads",
            a->threads,
            "Worker threads (0 = all cores); results do not change",
            kThreadsRange)
      ->capture_default_str();
  sub->add_option("--filter",
                  a->filters,
                  "GROUP=SPEC temporal filter, e.g. body=butterworth:6:4, left_hand=savgol:9:2, "
                  "instrument=oneeuro:1:0.5, all=none; repeatable, later wins");
  AddNumber(sub,
            "--max-gap-frames",
            a->max_gap_frames,
            "Fill NaN gaps up to this many frames before filtering (0 = none)",
            Closed(0, 1000000))
      ->capture_default_str();
  sub->parse_complete_callback([a] { ThrowIfInvalid(a->t.Validate()); });
  auto paths = [a] {
    PathRoles roles;
    AddCaptureInputs(&roles, "CAPTURE_DIR", a->capture_dir);
    roles.AddInput("--calibration", a->calibration);
    for (const std::string& v : a->views) roles.AddInput("--view", AssignedPath(v));
    roles.AddOutput("-o", a->output);
    return roles;
  };
  return CommandRun([a]() {
    a->t.refine = !a->no_refine;
    const bool views_mode = !a->views.empty() || !a->calibration.empty();
    if (views_mode && !a->capture_dir.empty()) {
      return PrintError("give either CAPTURE_DIR or --calibration with --view, not both");
    }
    if (views_mode) {
      if (a->calibration.empty()) return PrintError("--view needs --calibration");
      if (!a->filters.empty()) return PrintError("--filter applies to capture folders only");
      return RunViews(*a);
    }
    if (a->capture_dir.empty()) {
      return PrintError("give a CAPTURE_DIR, or --calibration CAL with --view CAMERA=LABELS");
    }
    if (!a->scale_instrument.empty()) return PrintError("--scale-to applies to labelled views");
    return RunCaptureFolder(*a);
  }, paths);
}

}  // namespace
ARCO_REGISTER_COMMAND(triangulate, 20, Setup);
}  // namespace arco::cli
