// `arco sync`: the audio offset of a video from a clap (or any sharp event).
#include <cstdio>
#include <memory>

#include "arco/cli/audio_report.h"
#include "arco/cli/command.h"
#include "arco/cli/flag_names.h"
#include "arco/cli/number_option.h"

namespace arco::cli {
namespace {

std::function<int()> SetupSync(CLI::App& app) {
  auto o = std::make_shared<capture::SyncRunOptions>();
  auto* cmd = app.add_subcommand(
      "sync", "Find a clap/flash in audio and video; print offset_s (audio = video + offset)");
  cmd->add_option("audio", o->audio, "Audio recording (or a video whose audio track to use)")
      ->required();
  cmd->add_option("--video",
                  o->videos,
                  "Video of a camera showing the event; repeat for several synchronised "
                  "cameras (their events must agree; default with --capture: every camera's "
                  "video)");
  AddNumber(cmd,
            "--fps",
            o->sync.video_fps,
            "Video frame rate (Hz; default: the stream's)",
            Closed(0, kVideoFpsRange.max));  // 0 = the stream's
  AddNumber(cmd,
            "--audio-near-s",
            o->sync.audio_near_s,
            "Look for the audio event near this time (s; default: strongest anywhere)",
            Closed(0, 86400));
  AddNumber(cmd,
            "--video-near-s",
            o->sync.video_near_s,
            "Look for the video event near this video time (s)",
            Closed(0, 86400));
  AddNumber(
      cmd, "--search-s", o->sync.search_s, "Half-width of the windows above (s)", AboveZero(3600))
      ->capture_default_str();
  AddNumber(cmd,
            "--max-s",
            o->sync.max_seconds,
            "Scan at most this much of each file (s)",
            AboveZero(86400))
      ->capture_default_str();
  auto event = std::make_shared<std::string>("clap");
  cmd->add_option("--event",
                  *event,
                  "clap: the end of a burst of motion (hands meeting); flash: a light or "
                  "slate switching on (a step in brightness)")
      ->check(CLI::IsMember({"clap", "flash"}))
      ->capture_default_str();
  cmd->add_option("--capture",
                  o->capture_dir,
                  "Capture folder: store the offset (audio time of frames.first) and its "
                  "confidence as audio.offset_s / audio.sync_confidence in its capture.json");
  return [o, event] {
    o->sync.video_event = *event == "flash" ? audio::VideoEvent::kFlash : audio::VideoEvent::kClap;
    auto result = capture::RunSync(*o);
    if (!result.ok()) return PrintError(WithFlagNames(result.status().message(), kSyncFlags));
    std::fputs(FormatSyncReport(*o, *result).c_str(), stdout);
    for (const std::string& w : SyncWarnings(*result)) PrintWarning(w);
    return 0;
  };
}

}  // namespace
ARCO_REGISTER_COMMAND(sync, 101, SetupSync);
}  // namespace arco::cli
