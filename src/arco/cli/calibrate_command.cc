// `arco calibrate --board SPEC --video CAM=FILE | --images CAM=DIR ... -o CALIBRATION`: a
// rig's intrinsics and extrinsics from board videos or image folders
// (calibration/calibrate.h; docs/calibration.md "Calibrating a rig"). Coexists with
// `arco calibration show|convert`, which inspects and converts existing files.
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "arco/calibrate/calibration_check.h"
#include "arco/calibrate/calibration_from_instrument.h"
#include "arco/calibrate/calibration_refine.h"
#include "arco/calibration/calibrate.h"
#include "arco/cli/command.h"
#include "arco/cli/command_paths.h"
#include "arco/cli/flag_names.h"
#include "arco/cli/number_option.h"
#include "arco/cli/progress.h"

namespace arco::cli {
namespace {

inline constexpr FieldFlag kCalibrateFlags[] = {{"frame_step", "--frame-step"},
                                                {"max_frames", "--max-frames"},
                                                {"max_intrinsic_views", "--intrinsic-views"},
                                                {"loss_scale_px", "--loss-px"},
                                                {"max_iterations", "--max-iterations"},
                                                {"num_threads", "--threads"},
                                                {"high_residual_px", "--high-residual-px"},
                                                {"min_views", "--min-views"}};

inline constexpr FieldFlag kCheckFlags[] = {{"min_score", "--min-score"},
                                            {"min_views", "--min-views"},
                                            {"flag_ratio", "--flag-ratio"},
                                            {"min_flag_px", "--min-flag-px"},
                                            {"frame_step", "--frame-step"}};

int RunCheck(const calibrate::CalibrationCheckOptions& options, bool json) {
  ProgressBar bar("check");
  auto result = calibrate::CheckCalibration(options, bar);
  bar.Finish();
  if (!result.ok()) return PrintError(WithFlagNames(result.status().message(), kCheckFlags));
  // Flagged cameras: exit kExitFoundProblems (after the report), as a linter does.
  const int status = result->flagged.empty() ? 0 : kExitFoundProblems;
  if (json) {
    std::printf("%s\n", result->ToJson().dump(2).c_str());
    return status;
  }
  std::printf("%s against %s: %lld frames; rig median %.2f px, flag above %.2f px\n",
              result->calibration.c_str(),
              options.label_views.empty() ? options.capture_dir.c_str() : "the labelled views",
              static_cast<long long>(result->frames),
              result->rig_median_px,
              result->threshold_px);
  std::printf("%-20s %10s %10s %10s  %s\n", "camera", "residuals", "median px", "p90 px", "");
  for (const auto& c : result->cameras) {
    std::string frames;
    for (const auto& [first, last] : c.off_frames)
      frames += (frames.empty() ? " frames " : ", ") + std::to_string(first) +
                (last != first ? "-" + std::to_string(last) : "");
    std::printf("%-20s %10lld %10.2f %10.2f  %s%s\n",
                c.name.c_str(),
                static_cast<long long>(c.residuals),
                c.median_px,
                c.p90_px,
                c.flagged ? "FLAGGED" : "",
                frames.c_str());
  }
  if (result->flagged.empty()) {
    std::printf("no camera flagged\n");
  } else {
    for (const auto& name : result->flagged)
      PrintWarning(name + ": residuals stand out from the rig's: moved or mis-calibrated?");
  }
  return status;
}

inline constexpr FieldFlag kRefineFlags[] = {{"min_score", "--min-score"},
                                             {"min_views", "--min-views"},
                                             {"max_frames", "--max-frames"},
                                             {"initial_gate_px", "--initial-gate-px"},
                                             {"gate_px", "--gate-px"},
                                             {"loss_scale_px", "--loss-px"},
                                             {"max_iterations", "--max-iterations"}};

int RunRefine(const calibrate::CalibrationRefineOptions& options) {
  ProgressBar bar("refine");
  auto result = calibrate::RefineCalibration(options, bar);
  bar.Finish();
  if (!result.ok()) return PrintError(WithFlagNames(result.status().message(), kRefineFlags));
  std::printf(
      "refined %s with %lld frames of %s: %lld points, instrument in %lld frames "
      "(string %.1f mm in the input's scale, %.1f mm now); reference camera %s held "
      "fixed\n",
      result->calibration.c_str(),
      static_cast<long long>(result->frames),
      options.capture_dir.c_str(),
      static_cast<long long>(result->points),
      static_cast<long long>(result->instrument_frames),
      result->string_length_before_mm,
      result->string_length_mm,
      result->reference_camera.c_str());
  std::printf("%-20s %8s %12s %11s %9s %10s %8s\n",
              "camera",
              "detections",
              "rms before",
              "rms after",
              "turned",
              "moved",
              "focal");
  for (const auto& c : result->cameras)
    std::printf("%-20s %8lld %9.2f px %8.2f px %7.3f° %7.2f mm %+7.4f%s\n",
                c.name.c_str(),
                static_cast<long long>(c.observations),
                c.rms_before_px,
                c.rms_after_px,
                c.rotation_change_deg,
                c.centre_change_mm,
                c.focal_change_rel,
                c.reference ? "  (reference)" : "");
  std::printf("reprojection rms %.2f px -> %.2f px\n", result->rms_before_px, result->rms_after_px);
  for (const auto& w : result->warnings) PrintWarning(w);
  std::printf("wrote %s and its .report.json\n", options.output.c_str());
  return 0;
}

inline constexpr FieldFlag kFromInstrumentFlags[] = {{"focal_px", "--focal-px"},
                                                     {"fov_deg", "--fov-deg"},
                                                     {"image_width", "--image-size"},
                                                     {"image_height", "--image-size"},
                                                     {"min_score", "--min-score"},
                                                     {"min_points", "--min-points"},
                                                     {"pnp_gate_px", "--pnp-gate-px"},
                                                     {"max_frames", "--max-frames"},
                                                     {"max_iterations", "--max-iterations"},
                                                     {"labels_frame", "--labels-frame"},
                                                     {"labels", "--labels"}};

int RunFromInstrument(const calibrate::CalibrationFromInstrumentOptions& options) {
  ProgressBar bar("from-instrument");
  auto result = calibrate::CalibrateFromInstrument(options, bar);
  bar.Finish();
  if (!result.ok())
    return PrintError(WithFlagNames(result.status().message(), kFromInstrumentFlags));
  if (result->cameras.size() == 1) {
    // One phone: the camera's intrinsics, and how well the instrument's model fits its
    // points; no rig, nothing refined or measured (calibration_from_instrument.h).
    const auto& c = result->cameras[0];
    std::printf(
        "calibrated 1 camera of %s: %dx%d (%s), focal %.1f px from %s; world: camera %s's "
        "frame, mm\n"
        "the %s's model fits its points in %d frames, reprojection rms %.2f px (median)\n",
        options.capture_dir.c_str(),
        c.width,
        c.height,
        c.size_source.c_str(),
        c.focal_px,
        result->focal_source.c_str(),
        c.name.c_str(),
        result->instrument.c_str(),
        c.pnp_frames,
        c.pnp_rms_px);
    for (const auto& w : result->warnings) PrintWarning(w);
    std::printf("wrote %s and its .report.json\n", options.output.c_str());
    return 0;
  }
  std::printf(
      "calibrated %zu cameras of %s from the %s: focal from %s; PnP poses in %d shared "
      "frames, initial rig from frame %lld; world: camera %s's frame, mm\n",
      result->cameras.size(),
      options.capture_dir.c_str(),
      result->instrument.c_str(),
      result->focal_source.c_str(),
      result->shared_frames,
      static_cast<long long>(result->reference_frame),
      result->rig.cameras[0].name.c_str());
  std::printf("%-20s %11s %8s %10s %10s %10s %10s\n",
              "camera",
              "size",
              "PnP fr.",
              "PnP px",
              "spread",
              "focal in",
              "focal out");
  for (const auto& c : result->cameras) {
    const std::string size = std::to_string(c.width) + "x" + std::to_string(c.height);
    std::printf("%-20s %11s %8d %10.2f %5.2f° %3.0fmm %10.1f %10.1f\n",
                c.name.c_str(),
                size.c_str(),
                c.pnp_frames,
                c.pnp_rms_px,
                c.relative_spread_deg,
                c.relative_spread_mm,
                c.initial_focal_px,
                c.focal_px);
  }
  std::printf(
      "string length (model %.1f mm): %.1f mm in the PnP rig's scale, %.1f mm +- %.1f "
      "triangulated with the result (%d frames); reprojection rms %.2f px -> %.2f px after the "
      "bundle adjustment\n",
      result->string_length_mm,
      result->string_length_initial_mm,
      result->string_length_measured_mm,
      result->string_length_spread_mm,
      result->string_length_frames,
      result->rms_initial_px,
      result->rms_px);
  for (const auto& w : result->warnings) PrintWarning(w);
  std::printf("wrote %s and its .report.json\n", options.output.c_str());
  return 0;
}

struct CalibrateArgs {
  calibration::CalibrateOptions options;
  std::vector<std::string> videos, images;
  bool fix_intrinsics = false;
};

std::string FormatReport(const calibration::CalibrateResult& result, const std::string& output) {
  const calibration::RigCalibrationReport& r = result.calibration.report;
  std::string text;
  char line[512];
  std::snprintf(line,
                sizeof(line),
                "calibrated %zu cameras from %s boards; world: %s, mm\n",
                r.cameras.size(),
                r.board.c_str(),
                r.origin.c_str());
  text += line;
  std::snprintf(line,
                sizeof(line),
                "%-16s %6s %6s %9s %9s %10s %10s %10s\n",
                "camera",
                "views",
                "used",
                "rms px",
                "p95 px",
                "fx",
                "cx",
                "cy");
  text += line;
  for (size_t c = 0; c < r.cameras.size(); ++c) {
    const auto& cam = r.cameras[c];
    const Camera& k = result.calibration.rig.cameras[c];
    std::snprintf(line,
                  sizeof(line),
                  "%-16s %6d %6d %9.3f %9.3f %10.2f %10.2f %10.2f\n",
                  cam.name.c_str(),
                  cam.views,
                  cam.views_used,
                  cam.rms_px,
                  cam.p95_px,
                  k.fx,
                  k.cx,
                  k.cy);
    text += line;
  }
  text += "shared frames:";
  for (const auto& p : r.pairs)
    text += " " + p.camera_a + "-" + p.camera_b + " " + std::to_string(p.shared_frames);
  text += "\n";
  std::snprintf(line,
                sizeof(line),
                "reprojection rms %.3f px; board triangulated: %.3f mm rms, %.3f mm p95 (%d "
                "points); bundle adjustment %s after %d iterations, %.2f s\n",
                r.rms_px,
                r.board_rms_mm,
                r.board_p95_mm,
                r.board_points,
                r.bundle_adjustment.termination.c_str(),
                r.bundle_adjustment.iterations,
                r.bundle_adjustment.time_s);
  text += line;
  text += "wrote " + output + " and " + result.report_path + "\n";
  return text;
}

// The cameras in the order --video and --images were given (the first is the default
// origin). Nothing to check when `arco calibrate check` is what runs.
void ApplyAndValidate(CalibrateArgs& a,
                      const CLI::App& cmd,
                      const CLI::App& check,
                      const CLI::App& refine,
                      const CLI::App& from_instrument) {
  if (check.parsed() || refine.parsed() || from_instrument.parsed()) return;
  if (a.options.board.empty()) ThrowIfInvalid(Status::Error("--board is required"));
  if (a.options.output.empty()) ThrowIfInvalid(Status::Error("--output is required"));
  a.options.inputs.clear();
  std::vector<std::pair<const std::string*, const char*>> given;
  size_t video = 0, image = 0;
  for (const CLI::Option* option : cmd.parse_order()) {
    if (option->get_name() == "--video" && video < a.videos.size())
      given.emplace_back(&a.videos[video++], "--video: ");
    if (option->get_name() == "--images" && image < a.images.size())
      given.emplace_back(&a.images[image++], "--images: ");
  }
  for (; video < a.videos.size(); ++video) given.emplace_back(&a.videos[video], "--video: ");
  for (; image < a.images.size(); ++image) given.emplace_back(&a.images[image], "--images: ");
  for (const auto& [text, flag] : given) {
    auto input = calibration::ParseCalibrateInput(*text);
    if (!input.ok()) ThrowIfInvalid(Status::Error(flag + input.status().message()));
    a.options.inputs.push_back(*input);
  }
  a.options.calibration.refine_intrinsics = !a.fix_intrinsics;
  const Status valid = a.options.Validate();
  if (!valid.ok()) ThrowIfInvalid(Status::Error(WithFlagNames(valid.message(), kCalibrateFlags)));
}

CommandRun SetupCalibrate(CLI::App& app) {
  auto a = std::make_shared<CalibrateArgs>();
  calibration::CalibrateOptions& o = a->options;
  auto* cmd = app.add_subcommand(
      "calibrate",
      "Calibrate a camera rig from videos or image folders of a board (intrinsics, "
      "extrinsics by bundle adjustment, a report in px and mm)");
  cmd->add_option("--board",
                  o.board,
                  "chessboard:COLSxROWS:SQUARE_MM (inner corners, e.g. chessboard:9x6:25) or "
                  "charuco:COLSxROWS:SQUARE_MM:MARKER_MM[:DICT] (squares; DICT default "
                  "DICT_4X4_50); required");
  cmd->add_option("--video",
                  a->videos,
                  "CAMERA=FILE: a camera's video of the board (repeat per camera; all "
                  "synchronised: frame n of every video is the same instant)");
  cmd->add_option("--images",
                  a->images,
                  "CAMERA=DIR: a camera's folder of images (natural order; image n of every "
                  "folder is the same instant), or one image");
  cmd->add_option("--intrinsics",
                  o.intrinsics,
                  "Calibration file whose cameras (by name) give intrinsics to start from");
  cmd->add_flag("--fix-intrinsics",
                a->fix_intrinsics,
                "Keep the intrinsics (given or initial) fixed in the bundle adjustment");
  cmd->add_option("--origin",
                  o.calibration.origin,
                  "World frame: a camera's name (default: the first camera given) or 'board' "
                  "(the board in the first frame two cameras see)");
  AddNumber(cmd,
            "--max-frames",
            o.detection.max_frames,
            "Look at most at this many frames per camera (0 = all)",
            calibration::kMaxFramesRange)
      ->capture_default_str();
  AddNumber(cmd,
            "--frame-step",
            o.detection.frame_step,
            "Look at every n-th frame",
            calibration::kFrameStepRange)
      ->capture_default_str();
  AddNumber(cmd,
            "--intrinsic-views",
            o.calibration.max_intrinsic_views,
            "Views per camera (chosen to cover the image) for the initial intrinsics",
            calibration::kIntrinsicViewsRange)
      ->capture_default_str();
  AddNumber(cmd,
            "--loss-px",
            o.calibration.loss_scale_px,
            "Huber loss scale of the bundle adjustment (px)",
            calibration::kLossScaleRangePx)
      ->capture_default_str();
  AddNumber(cmd,
            "--max-iterations",
            o.calibration.max_iterations,
            "Bundle adjustment iterations at most",
            calibration::kIterationsRange)
      ->capture_default_str();
  AddNumber(cmd,
            "--high-residual-px",
            o.calibration.high_residual_px,
            "Warn about a camera whose reprojection RMS is above this (px)",
            calibration::kHighResidualRangePx)
      ->capture_default_str();
  AddNumber(cmd,
            "--min-views",
            o.calibration.min_views,
            "Warn about a camera with fewer board views",
            calibration::kMinViewsRange)
      ->capture_default_str();
  AddNumber(
      cmd,
      "--threads",
      o.num_threads,
      "Cameras whose board detection runs at once (0 = all cores; results do not depend on it)",
      kThreadsRange)
      ->capture_default_str();
  cmd->add_option("-o,--output",
                  o.output,
                  "Calibration to write: .json arco JSON, .yaml/.yml OpenCV YAML, .xml OpenCV "
                  "XML; the report goes beside it as NAME.report.json; required");
  auto c = std::make_shared<calibrate::CalibrationCheckOptions>();
  auto json = std::make_shared<bool>(false);
  auto* check = cmd->add_subcommand(
      "check",
      "Check a calibration against a capture's 2D keypoints (or a result's points): per "
      "camera the reprojection residuals of the triangulated keypoints; a camera that stands out "
      "(moved or "
      "mis-calibrated) is flagged with its frames");
  check->add_option("capture",
                    c->capture_dir,
                    "Capture folder (capture.json, keypoints2d), or a result folder (its "
                    "triangulated points against the capture its result.json names)");
  auto views = std::make_shared<std::vector<std::string>>();
  check->add_option("--view",
                    *views,
                    "CAMERA=LABELME.json: check labelled views instead of a capture (CAMERA a "
                    "camera name or serial; repeat per view; needs --calibration)");
  check->add_option("--calibration",
                    c->calibration,
                    "Calibration to check instead of the capture's own (any format arco reads)");
  AddNumber(
      check, "--min-score", c->min_score, "Ignore detections below this confidence", kFractionRange)
      ->capture_default_str();
  AddNumber(check,
            "--min-views",
            c->min_views,
            "Use keypoints triangulated from at least this many cameras",
            Closed(2, 1000))
      ->capture_default_str();
  AddNumber(check,
            "--flag-ratio",
            c->flag_ratio,
            "Flag a camera whose median residual exceeds this times the rig's median",
            calibrate::kCheckRatioRange)
      ->capture_default_str();
  AddNumber(check,
            "--min-flag-px",
            c->min_flag_px,
            "... and this many pixels (px)",
            calibrate::kCheckMinFlagRangePx)
      ->capture_default_str();
  AddNumber(
      check, "--frame-step", c->frame_step, "Check every n-th frame", calibration::kFrameStepRange)
      ->capture_default_str();
  check->add_flag("--json", *json, "Print the summary as JSON");
  check->parse_complete_callback([c, views] {
    c->label_views.clear();
    for (const std::string& text : *views) {
      auto view = calibration::ParseCalibrateInput(text);
      if (!view.ok()) ThrowIfInvalid(Status::Error("--view: " + view.status().message()));
      c->label_views.emplace_back(view->camera, view->path);
    }
    if (!c->label_views.empty() && !c->capture_dir.empty())
      ThrowIfInvalid(Status::Error("give a capture or --view labels, not both"));
    if (c->label_views.empty() && c->capture_dir.empty())
      ThrowIfInvalid(Status::Error("give a capture folder or --view labels"));
    if (!c->label_views.empty() && c->calibration.empty())
      ThrowIfInvalid(Status::Error("--view needs --calibration"));
    const Status valid = c->Validate();
    if (!valid.ok()) ThrowIfInvalid(Status::Error(WithFlagNames(valid.message(), kCheckFlags)));
  });
  auto r = std::make_shared<calibrate::CalibrationRefineOptions>();
  auto* refine = cmd->add_subcommand(
      "refine",
      "Refine a calibration's extrinsics (and optionally focal lengths) by bundle adjustment "
      "over a capture's 2D keypoints and the instrument as a rigid body of known size");
  refine->add_option("capture", r->capture_dir, "Capture folder (capture.json, keypoints2d)")
      ->required();
  refine->add_option("--calibration",
                     r->calibration,
                     "Calibration to refine instead of the capture's own (any format arco reads)");
  refine
      ->add_option("-o,--output",
                   r->output,
                   "Refined calibration to write: .json arco JSON, .yaml/.yml OpenCV YAML, "
                   ".xml OpenCV XML; the report goes beside it as NAME.report.json; required")
      ->required();
  refine->add_flag("--overwrite", r->overwrite, "Replace an existing output file");
  refine->add_option("--reference",
                     r->reference_camera,
                     "Camera held fixed, which keeps the world frame (default: the capture's "
                     "first camera)");
  refine->add_flag("--refine-focal", r->refine_focal, "Also refine every camera's fx and fy");
  AddNumber(refine,
            "--min-score",
            r->min_score,
            "Ignore detections below this confidence",
            kFractionRange)
      ->capture_default_str();
  AddNumber(refine,
            "--min-views",
            r->min_views,
            "Use keypoints seen by at least this many cameras that agree",
            Closed(2, 1000))
      ->capture_default_str();
  AddNumber(refine,
            "--max-frames",
            r->max_frames,
            "Use at most this many frames, evenly spread over the capture",
            calibrate::kRefineMaxFramesRange)
      ->capture_default_str();
  AddNumber(refine,
            "--initial-gate-px",
            r->initial_gate_px,
            "First pass: leave out views farther than this from their point (px)",
            calibrate::kRefineGateRangePx)
      ->capture_default_str();
  AddNumber(refine,
            "--gate-px",
            r->gate_px,
            "Last pass: keep views within this residual (px)",
            calibrate::kRefineGateRangePx)
      ->capture_default_str();
  AddNumber(refine,
            "--loss-px",
            r->loss_scale_px,
            "Cauchy loss scale of the last pass (px)",
            calibrate::kRefineLossRangePx)
      ->capture_default_str();
  AddNumber(refine,
            "--max-iterations",
            r->max_iterations,
            "Bundle adjustment iterations per pass at most",
            calibrate::kRefineIterationsRange)
      ->capture_default_str();
  refine->parse_complete_callback([r] {
    const Status valid = r->Validate();
    if (!valid.ok()) ThrowIfInvalid(Status::Error(WithFlagNames(valid.message(), kRefineFlags)));
  });
  auto fi = std::make_shared<calibrate::CalibrationFromInstrumentOptions>();
  auto image_size = std::make_shared<std::string>();
  auto fix_focal = std::make_shared<bool>(false);
  auto labels = std::make_shared<std::vector<std::string>>();
  auto* from_instrument = cmd->add_subcommand(
      "from-instrument",
      "Calibrate two or more cameras without a board, from the take itself: each camera's "
      "pose by PnP of the instrument's 2D points against its model (whose real size gives "
      "the scale), then refined by bundle adjustment with the performer and the instrument. "
      "One camera: its intrinsics, its frame the world, and how well the model fits");
  from_instrument
      ->add_option("capture",
                   fi->capture_dir,
                   "Capture folder (capture.json with the instrument, keypoints2d with its "
                   "points in every camera); its own calibration is not used")
      ->required();
  from_instrument
      ->add_option("-o,--output",
                   fi->output,
                   "Calibration to write: .json arco JSON, .yaml/.yml OpenCV YAML, .xml OpenCV "
                   "XML; the report goes beside it as NAME.report.json; required")
      ->required();
  from_instrument->add_flag("--overwrite", fi->overwrite, "Replace an existing output file");
  AddNumber(from_instrument,
            "--focal-px",
            fi->focal_px,
            "Every camera's focal length to start from (px); default: from --fov-deg",
            calibrate::kFromInstrumentFocalRangePx);
  AddNumber(from_instrument,
            "--fov-deg",
            fi->fov_deg,
            "Field of view across the image's longer side to start from (degrees); default: a "
            "phone's main camera, 67 (26 mm equivalent)",
            calibrate::kFromInstrumentFovRangeDeg);
  from_instrument->add_option(
      "--image-size",
      *image_size,
      "WIDTHxHEIGHT of every camera's image (px); default: read from each camera's video");
  from_instrument->add_flag(
      "--fix-focal", *fix_focal, "Keep the focal lengths in the bundle adjustment");
  AddNumber(from_instrument,
            "--min-score",
            fi->min_score,
            "Ignore detections below this confidence",
            kFractionRange)
      ->capture_default_str();
  AddNumber(from_instrument,
            "--min-points",
            fi->min_points,
            "Instrument points a camera needs in a frame for a PnP pose",
            calibrate::kFromInstrumentPointsRange)
      ->capture_default_str();
  AddNumber(from_instrument,
            "--pnp-gate-px",
            fi->pnp_gate_px,
            "RANSAC inlier threshold of the PnP (px)",
            calibrate::kFromInstrumentGateRangePx)
      ->capture_default_str();
  AddNumber(from_instrument,
            "--max-frames",
            fi->max_frames,
            "Bundle adjustment: use at most this many frames, evenly spread",
            calibrate::kRefineMaxFramesRange)
      ->capture_default_str();
  AddNumber(from_instrument,
            "--max-iterations",
            fi->max_iterations,
            "Bundle adjustment iterations per pass at most",
            calibrate::kRefineIterationsRange)
      ->capture_default_str();
  from_instrument->add_option(
      "--labels",
      *labels,
      "CAMERA=LABELME.json: the instrument's points labelled in one frame (--labels-frame) of "
      "each camera, as `arco track --labels` takes them, put in every frame in place of "
      "keypoints2d's (a starting calibration; docs/phones.md); one per camera");
  AddNumber(from_instrument,
            "--labels-frame",
            fi->labels_frame,
            "Capture frame the labels are on (-1 = the capture's first frame), as `arco track`'s",
            Closed(-1, 1e12))
      ->capture_default_str();
  from_instrument->parse_complete_callback([fi, image_size, fix_focal, labels] {
    fi->refine_focal = !*fix_focal;
    fi->labels.clear();
    for (const std::string& text : *labels) {
      const size_t eq = text.find('=');
      if (eq == std::string::npos || eq == 0 || eq + 1 == text.size() || text.find('@') < eq)
        ThrowIfInvalid(Status::Error("--labels \"" + text +
                                     "\" must look like CAMERA=LABELME.json (the labels of "
                                     "--labels-frame)"));
      fi->labels.push_back({text.substr(0, eq), text.substr(eq + 1)});
    }
    if (!image_size->empty()) {
      int w = 0, h = 0;
      char x = 0, extra = 0;
      if (std::sscanf(image_size->c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || x != 'x' ||
          w <= 0 || h <= 0)
        ThrowIfInvalid(Status::Error("--image-size: '" + *image_size +
                                     "' is not WIDTHxHEIGHT in pixels (e.g. 1920x1080)"));
      fi->image_width = w, fi->image_height = h;
    }
    const Status valid = fi->Validate();
    if (!valid.ok())
      ThrowIfInvalid(Status::Error(WithFlagNames(valid.message(), kFromInstrumentFlags)));
  });
  cmd->parse_complete_callback([a, cmd, check, refine, from_instrument] {
    ApplyAndValidate(*a, *cmd, *check, *refine, *from_instrument);
  });
  // calibrate check writes nothing; calibrate and calibrate refine write a calibration and
  // its report beside it.
  auto paths = [a, r, fi, check, refine, from_instrument] {
    PathRoles roles;
    // capture.json read once: its files listed here, the manifest handed to the command.
    auto add_capture = [&roles](const std::string& capture_dir,
                                std::optional<CaptureManifest>* manifest) {
      if (capture_dir.empty()) return;
      StatusOr<CaptureManifest> read = ReadCaptureManifest(capture_dir);
      if (!read.ok()) {  // the command reports it, reading it again
        roles.AddInput("CAPTURE", capture_dir);
        return;
      }
      AddCaptureInputs(&roles, "CAPTURE", capture_dir, *read);
      *manifest = std::move(read).value();
    };
    if (from_instrument->parsed()) {
      add_capture(fi->capture_dir, &fi->capture_manifest);
      for (const auto& l : fi->labels) roles.AddInput("--labels", l.path);
      roles.AddOutput("-o", fi->output);
      if (!fi->output.empty()) {
        roles.AddOutput("-o's report", calibration::ReportPath(fi->output));
      }
    } else if (refine->parsed()) {
      add_capture(r->capture_dir, &r->capture_manifest);
      roles.AddInput("--calibration", r->calibration);
      roles.AddOutput("-o", r->output);
      if (!r->output.empty()) {
        roles.AddOutput("-o's report", calibration::ReportPath(r->output));
      }
    } else if (!check->parsed()) {
      for (const std::string& v : a->videos) roles.AddInput("--video", AssignedPath(v));
      for (const std::string& v : a->images) roles.AddInput("--images", AssignedPath(v));
      roles.AddInput("--intrinsics", a->options.intrinsics);
      roles.AddOutput("-o", a->options.output);
      if (!a->options.output.empty()) {
        roles.AddOutput("-o's report", calibration::ReportPath(a->options.output));
      }
    }
    return roles;
  };
  return CommandRun(
      [a, c, r, fi, json, check, refine, from_instrument] {
        if (check->parsed()) return RunCheck(*c, *json);
        if (from_instrument->parsed()) return RunFromInstrument(*fi);
        if (refine->parsed()) return RunRefine(*r);
        ProgressBar bar("calibrate");
        auto result = calibration::RunCalibrate(a->options, bar);
        bar.Finish();
        if (!result.ok())
          return PrintError(WithFlagNames(result.status().message(), kCalibrateFlags));
        std::fputs(FormatReport(*result, a->options.output).c_str(), stdout);
        for (const auto& w : result->calibration.report.warnings)
          PrintWarning(w.code + ": " + w.message);
        return 0;
      },
      paths);
}

}  // namespace
ARCO_REGISTER_COMMAND(calibrate, 21, SetupCalibrate);
}  // namespace arco::cli
