// `arco import-spd`: SPD per-frame 2D keypoint folders -> an arco capture folder.
#include <cstdio>
#include <memory>

#include "arco/capture/import_spd.h"
#include "arco/cli/command.h"
#include "arco/cli/flag_names.h"
#include "arco/cli/number_option.h"

namespace arco::cli {
namespace {

// ImportSpdOptions' fields as `arco import-spd` sets them.
inline constexpr FieldFlag kImportSpdFlags[] = {{"frame_first", "--first"},
                                                {"frame_last", "--last"}};

CommandRun Setup(CLI::App& app) {
  auto o = std::make_shared<capture::ImportSpdOptions>();
  CLI::App* sub = app.add_subcommand(
      "import-spd",
      "Turn SPD per-frame 2D keypoint folders (HUMAN_DIR/<serial>/<n>.json, bare NaN, "
      "FrameDropIDLog) into a capture folder for `arco triangulate CAPTURE_DIR`");
  sub->add_option("--calibration", o->calibration, "Calibration of the session (copied)")
      ->required();
  sub->add_option("--human", o->human_dir, "Folder of 133-point (or full) per-frame files")
      ->required();
  sub->add_option("--instrument-points",
                  o->instrument_dir,
                  "Folder of 9 (cello) / 7 (violin) instrument-point per-frame files");
  sub->add_option(
      "--summary", o->summary, "SESSION_summary.json: StartFrame, EndFrame and FrameDropIDLog");
  sub->add_option("--instrument", o->instrument, "cello or violin")
      ->check(CLI::IsMember({"cello", "violin"}))
      ->capture_default_str();
  sub->add_option("--serials",
                  o->serials,
                  "Cameras in view order (default: every calibrated camera with a folder)");
  AddNumber(sub,
            "--first",
            o->frame_first,
            "First global frame (default: StartFrame)",
            Closed(1, kFrameCountRange.max));
  AddNumber(sub,
            "--last",
            o->frame_last,
            "Last global frame, inclusive (default: EndFrame)",
            Closed(1, kFrameCountRange.max));
  AddNumber(sub, "--fps", o->fps, "Video frame rate, frames per second", kVideoFpsRange)
      ->capture_default_str();
  sub->add_option("--audio", o->audio, "Audio file of the session (copied)");
  AddNumber(sub,
            "--audio-offset-s",
            o->audio_offset_s,
            "Audio time (s) at the start of the first frame",
            kAudioTimeRangeS)
      ->capture_default_str();
  sub->add_option("--name", o->name, "Session name (default: the output folder's name)");
  sub->add_option("-o,--output",
                  o->output_dir,
                  "Capture folder to create (must not exist, unless --overwrite)")
      ->required();
  sub->add_flag("--overwrite", o->overwrite, "Replace an existing capture folder");
  auto paths = [o] {
    PathRoles roles;
    roles.AddInput("--calibration", o->calibration);
    roles.AddInput("--human", o->human_dir);
    roles.AddInput("--instrument-points", o->instrument_dir);
    roles.AddInput("--summary", o->summary);
    roles.AddInput("--audio", o->audio);
    roles.AddOutput("-o", o->output_dir);
    return roles;
  };
  return CommandRun(
      [o]() {
        auto r = capture::ImportSpdCapture(*o);
        if (!r.ok()) return PrintError(WithFlagNames(r.status().message(), kImportSpdFlags));
        std::printf(
            "imported %lld frames x %lld views x %lld points (%lld files read, %lld missing -> "
            "NaN, "
            "%lld dropped frames) -> %s\n",
            static_cast<long long>(r->frames),
            static_cast<long long>(r->views),
            static_cast<long long>(r->points),
            static_cast<long long>(r->files.files_read),
            static_cast<long long>(r->files.files_missing),
            static_cast<long long>(r->files.frames_dropped),
            o->output_dir.c_str());
        for (const std::string& w : r->warnings) PrintWarning(w);
        return 0;
      },
      paths);
}

}  // namespace
ARCO_REGISTER_COMMAND(import_spd, 19, Setup);
}  // namespace arco::cli
