// `arco view`: a result folder as a local web page with its audio (docs/view.md), served
// on 127.0.0.1 or written as a folder that opens from disk (--no-serve -o DIR).
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "arco/cli/command.h"
#include "arco/cli/command_paths.h"
#include "arco/cli/number_option.h"
#include "arco/util/interrupt.h"
#include "arco/util/output_set.h"
#include "arco/view/server.h"
#include "arco/view/video_cache.h"
#include "arco/view/view.h"

namespace arco::cli {
namespace {

struct Args {
  view::ViewOptions options;
  int port = 8765;
  double exit_after_s = 0;
  bool no_serve = false;
  bool overwrite = false;
  bool no_videos = false;
  bool no_cache = false;
  std::string output;
};

void PrintMissing(const view::ViewSummary& summary) {
  for (const auto& m : summary.missing) {
    std::fprintf(stderr, "arco view: %s is missing: %s\n", m.stage.c_str(), m.why.c_str());
  }
}

void PrintShown(const Args& a, const view::ViewSummary& summary) {
  std::string methods;
  for (const auto& m : summary.methods) methods += (methods.empty() ? "" : ", ") + m;
  std::printf("arco view: %s: %lld frames, methods %s, audio %s, %.1f MB of arrays\n",
              a.options.result_dir.c_str(),
              static_cast<long long>(summary.frames),
              methods.c_str(),
              summary.audio.empty() ? "none" : summary.audio.c_str(),
              summary.bytes / 1e6);
  for (const auto& v : summary.videos) {
    std::printf("arco view: video of %s (%dx%d, %lld frames, %s overlay, %s) %s in %.1f s\n",
                v.camera.c_str(),
                v.width,
                v.height,
                static_cast<long long>(v.frames),
                v.method.c_str(),
                v.source.empty() ? "no video: black" : v.source.c_str(),
                v.cached ? "taken from the cache" : "encoded",
                v.seconds);
  }
  if (!summary.videos.empty()) {
    std::printf("arco view: videos: %d encoded, %d from the cache (%s), %d cache entries removed\n",
                summary.videos_encoded,
                summary.videos_cached,
                a.options.cache_dir.empty() ? "no cache" : a.options.cache_dir.c_str(),
                summary.cache_evicted);
  }
}

int WriteFolder(Args a) {
  a.options.embed_data = true;
  OutputSet outputs;
  FolderReplace replace;
  replace.overwrite = a.overwrite;
  replace.marker = "manifest.json";
  replace.kind = "viewer folder";
  auto tmp = outputs.AddFolder(a.output, replace);
  if (!tmp.ok()) return PrintError(tmp.status().message());
  auto summary = view::WriteViewFolder(a.options, *tmp);
  if (!summary.ok()) return PrintError(summary.status().message());
  const Status committed = outputs.Commit();
  if (!committed.ok()) return PrintError(committed.message());
  PrintMissing(*summary);
  PrintShown(a, *summary);
  std::printf("open %s/index.html in a browser (works from disk, no server)\n", a.output.c_str());
  return 0;
}

int Serve(const Args& a) {
  std::string pattern = (std::filesystem::temp_directory_path() / "arco-view-XXXXXX").string();
  bool made = false;
  {
    // Made and registered together, before or after an interrupt's cleanup takes its list
    // (no message under the lock: the error path waits for the cleanup if interrupted).
    const std::unique_lock<std::mutex> no_interrupt = HoldOffInterrupts();
    made = mkdtemp(pattern.data()) != nullptr;
    if (made) TrackTemporary(pattern);  // an interrupt before the server listens removes it too
  }
  if (!made) return PrintError(pattern + ": cannot create");
  const std::string dir = pattern;
  auto summary = view::WriteViewFolder(a.options, dir);
  int rc = 0;
  if (!summary.ok()) {
    rc = PrintError(summary.status().message());
  } else {
    view::ServeOptions serve;
    serve.dir = dir;
    serve.port = a.port;
    serve.exit_after_s = a.exit_after_s;
    // Printed once the port is bound: a busy port is the error line alone.
    const Status served = view::ServeFolder(serve, [&](int port) {
      PrintMissing(*summary);
      PrintShown(a, *summary);
      std::printf("arco view: http://127.0.0.1:%d/ (Ctrl-C stops)\n", port);
      std::fflush(stdout);
    });
    if (!served.ok()) rc = PrintError(served.message());
  }
  std::error_code ignored;
  std::filesystem::remove_all(dir, ignored);
  UntrackTemporary(dir);
  return rc;
}

CommandRun SetupView(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "view", "See and hear a result: 3D, audio, pitch, contacts in a local web page");
  auto a = std::make_shared<Args>();
  cmd->add_option("result_dir", a->options.result_dir, "Result folder (from arco run)")->required();
  AddNumber(cmd,
            "--port",
            a->port,
            "Port on 127.0.0.1 (0: any free port; the URL is printed)",
            Closed(0, 65535))
      ->capture_default_str();
  AddNumber(cmd,
            "--exit-after-s",
            a->exit_after_s,
            "Stop serving after this many seconds (0: until Ctrl-C)",
            Closed(0, 86400))
      ->capture_default_str();
  cmd->add_flag("--no-serve",
                a->no_serve,
                "Write the page to -o DIR (opens from disk: the data embedded in data.js)");
  cmd->add_option("-o,--output", a->output, "Output folder of --no-serve");
  cmd->add_flag("--overwrite", a->overwrite, "Replace an existing viewer folder");
  cmd->add_option("--video-camera",
                  a->options.video_cameras,
                  "A camera whose video is shown with the overlay (name or serial; repeatable; "
                  "default: the first camera with a video)");
  cmd->add_flag("--no-videos",
                a->no_videos,
                "Show no camera video (writing one takes about the take's duration)");
  AddNumber(cmd,
            "--video-scale",
            a->options.video_scale,
            "Size of the videos as a fraction of the calibration's image size",
            view::kViewVideoScaleRange)
      ->capture_default_str();
  a->options.cache_dir = view::DefaultVideoCacheDir();
  auto* cache_dir =
      cmd->add_option("--cache-dir",
                      a->options.cache_dir,
                      "Cache of the encoded videos, reused while their inputs are unchanged "
                      "(default: $XDG_CACHE_HOME/arco/view, else ~/.cache/arco/view)");
  cmd->add_flag("--no-cache", a->no_cache, "Encode the videos again and cache nothing");
  AddNumber(cmd,
            "--cache-max-gb",
            a->options.cache_max_gb,
            "Size of the video cache; the least recently used videos beyond it are removed",
            view::kViewCacheMaxGbRange)
      ->capture_default_str();
  cmd->parse_complete_callback([a, cache_dir] {
    if (a->no_serve && a->output.empty()) {
      throw CLI::ValidationError("--no-serve needs -o DIR");
    }
    if (!a->no_serve && !a->output.empty()) {
      throw CLI::ValidationError("-o is for --no-serve (the server writes no folder)");
    }
    if (a->no_videos && !a->options.video_cameras.empty()) {
      throw CLI::ValidationError("--no-videos and --video-camera contradict each other");
    }
    a->options.videos = !a->no_videos;
    if (a->no_cache && cache_dir->count() > 0) {
      throw CLI::ValidationError("--no-cache and --cache-dir contradict each other");
    }
    if (a->no_cache) a->options.cache_dir.clear();
    if (!a->no_cache && a->options.cache_dir.empty() && a->options.videos) {
      throw CLI::ValidationError(
          "--cache-dir: no cache folder (HOME and XDG_CACHE_HOME are unset): give one or "
          "--no-cache");
    }
    ThrowIfInvalid(a->options.Validate());
  });
  return CommandRun([a] { return a->no_serve ? WriteFolder(*a) : Serve(*a); },
                    [a] {
                      PathRoles roles;
                      AddResultInputs(&roles, "RESULT_DIR", a->options.result_dir);
                      if (a->no_serve) roles.AddOutput("-o", a->output);
                      return roles;
                    });
}

}  // namespace
ARCO_REGISTER_COMMAND(view, 76, SetupView);
}  // namespace arco::cli
