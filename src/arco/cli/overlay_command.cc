// `arco overlay`: a result drawn into one camera's video (docs/export.md, "Overlay").
#include <cstdio>

#include "arco/cli/command.h"
#include "arco/cli/command_paths.h"
#include "arco/cli/flag_names.h"
#include "arco/cli/frame_range.h"
#include "arco/cli/number_option.h"
#include "arco/export/overlay.h"
#include "arco/util/output_set.h"

namespace arco::cli {
namespace {

inline constexpr FieldFlag kOverlayFlags[] = {{"result_dir", "RESULT_DIR"},
                                              {"method", "--method"},
                                              {"scale", "--scale"},
                                              {"first_frame", "--frames"},
                                              {"last_frame", "--frames"}};

struct Args {
  exporter::OverlayOptions options;
  std::string frames;  // FIRST:LAST
  std::string output;
};

int Run(const Args& a) {
  OutputSet outputs;
  auto tmp = outputs.AddFile(a.output);
  if (!tmp.ok()) return PrintError(tmp.status().message());
  auto summary = exporter::WriteOverlay(a.options, *tmp, a.output);
  if (!summary.ok()) return PrintError(WithFlagNames(summary.status().message(), kOverlayFlags));
  const Status committed = outputs.Commit();
  if (!committed.ok()) return PrintError(committed.message());
  std::printf(
      "arco overlay: method %s on camera %s (%s), frames %lld:%lld, %lld frames at %g fps, "
      "%dx%d %s -> %s\n",
      a.options.method.c_str(),
      summary->camera.c_str(),
      summary->video.empty() ? "no video: blank frames" : summary->video.c_str(),
      static_cast<long long>(summary->first_frame),
      static_cast<long long>(summary->last_frame),
      static_cast<long long>(summary->frames),
      summary->fps,
      summary->width,
      summary->height,
      summary->codec.c_str(),
      a.output.c_str());
  if (summary->frames_without_video > 0) {
    std::printf("%lld frames the camera dropped are drawn on a blank frame\n",
                static_cast<long long>(summary->frames_without_video));
  }
  return 0;
}

CommandRun SetupOverlay(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "overlay",
      "Draw a result (skeleton, strings, contact, fingers, note) into one camera's video");
  auto a = std::make_shared<Args>();
  cmd->add_option("result_dir", a->options.result_dir, "Result folder (from arco run)")->required();
  cmd->add_option("--camera",
                  a->options.camera,
                  "Capture camera (name or serial); its video, or a blank frame without one")
      ->required();
  cmd->add_option("--method", a->options.method, "Which method's points: arco, paper or vision")
      ->capture_default_str();
  cmd->add_option("--frames", a->frames, "FIRST:LAST result frame numbers (default all)");
  AddNumber(cmd,
            "--scale",
            a->options.scale,
            "Output size relative to the calibration's image size",
            exporter::kOverlayScaleRange)
      ->capture_default_str();
  cmd->add_option(
         "-o,--output",
         a->output,
         "Output video: .mp4/.mov (H.264, else MPEG-4), .mkv (FFV1, lossless), .avi, .webm (VP8)")
      ->required();
  cmd->parse_complete_callback([a] {
    ThrowIfInvalid(ParseFrameRange(a->frames, &a->options.first_frame, &a->options.last_frame));
    const Status valid = a->options.Validate();
    if (!valid.ok()) throw CLI::ValidationError(WithFlagNames(valid.message(), kOverlayFlags));
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
ARCO_REGISTER_COMMAND(overlay, 76, SetupOverlay);
}  // namespace arco::cli
