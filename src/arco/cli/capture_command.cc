// `arco capture new`: a capture folder that references videos (capture/capture_new.h);
// `arco capture import-keypoints`: another detector's 2D keypoints into a capture
// (capture/import_keypoints.h).
#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "arco/capture/capture_new.h"
#include "arco/capture/import_keypoints.h"
#include "arco/cli/command.h"
#include "arco/cli/command_paths.h"
#include "arco/cli/flag_names.h"
#include "arco/cli/number_option.h"
#include "arco/mocap/capture.h"

namespace arco::cli {
namespace {

// Fields of CaptureNewOptions / ImportKeypointsOptions as their flags.
inline constexpr FieldFlag kCaptureFlags[] = {{"inputs", "--video/--images"},
                                              {"calibration", "--calibration"},
                                              {"rotate_deg", "--rotate"},
                                              {"dropped_frames", "--dropped-frames"},
                                              {"spd_summary", "--spd-summary"},
                                              {"fps", "--fps"},
                                              {"sync_max_seconds", "--sync-max-seconds"},
                                              {"sync audio", "--sync audio"},
                                              {"output_dir", "-o"},
                                              {"format", "--format"},
                                              {"sources", "--camera"},
                                              {"pixels = decoded", "--pixels decoded"},
                                              {"pixels = calibration", "--pixels calibration"},
                                              {"an input with images set", "given with --images"}};

// "CAMERA=VALUE" -> {CAMERA, VALUE}; throws CLI::ValidationError naming the flag and the
// expected `form`.
std::pair<std::string, std::string> SplitAssignment(const std::string& flag,
                                                    const std::string& text,
                                                    const std::string& form) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size()) {
    throw CLI::ValidationError(flag + ": " + text + " is not " + form);
  }
  return {text.substr(0, eq), text.substr(eq + 1)};
}

// A whole number in [min, max] written in full, or a CLI::ValidationError naming the flag.
int64_t ParseWhole(const std::string& flag, const std::string& text, int64_t min, int64_t max) {
  char* end = nullptr;
  errno = 0;
  const long long value = text.empty() ? 0 : std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE || value < min || value > max) {
    throw CLI::ValidationError(flag + ": " + text + " is not a whole number in [" +
                               std::to_string(min) + ", " + std::to_string(max) + "]");
  }
  return value;
}

struct CaptureNewArgs {
  std::vector<std::string> videos, images, rotate, drops;
  std::string sync = "none";
  capture::CaptureNewOptions options;
  // The typed options from the CAMERA=VALUE lists (parse-complete).
  void Convert() {
    auto& o = options;
    o.sync = sync == "audio" ? capture::CaptureSync::kAudio : capture::CaptureSync::kNone;
    o.inputs.clear();
    for (const std::string& v : videos) {
      const auto [camera, path] = SplitAssignment("--video", v, "CAMERA=FILE");
      o.inputs.push_back({camera, path, false});
    }
    for (const std::string& v : images) {
      const auto [camera, path] = SplitAssignment("--images", v, "CAMERA=DIR");
      o.inputs.push_back({camera, path, true});
    }
    o.rotate_deg.clear();
    for (const std::string& r : rotate) {
      const auto [camera, deg] = SplitAssignment("--rotate", r, "CAMERA=DEGREES");
      const int64_t value = ParseWhole("--rotate", deg, 0, 270);
      if (value % 90 != 0) {
        throw CLI::ValidationError("--rotate: " + r + ": the rotation must be 0, 90, 180 or 270");
      }
      if (!o.rotate_deg.emplace(camera, static_cast<int>(value)).second) {
        throw CLI::ValidationError("--rotate: camera " + camera + " is given twice");
      }
    }
    o.dropped_frames.clear();
    for (const std::string& d : drops) {
      const auto [camera, list] = SplitAssignment("--dropped-frames", d, "CAMERA=FRAME,FRAME,...");
      std::vector<int64_t> frames;
      for (size_t at = 0; at <= list.size();) {
        const size_t comma = std::min(list.find(',', at), list.size());
        frames.push_back(ParseWhole(
            "--dropped-frames", list.substr(at, comma - at), 1, static_cast<int64_t>(1e9)));
        at = comma + 1;
      }
      if (!o.dropped_frames.emplace(camera, frames).second) {
        throw CLI::ValidationError("--dropped-frames: camera " + camera + " is given twice");
      }
    }
  }
};

int RunCaptureNew(const capture::CaptureNewOptions& o) {
  auto r = capture::CreateCapture(o);
  if (!r.ok()) return PrintError(WithFlagNames(r.status().message(), kCaptureFlags));
  const bool synced = o.sync == capture::CaptureSync::kAudio;
  for (const capture::CaptureNewCamera& c : r->cameras) {
    if (synced) {
      std::printf("  %-12s starts at %+.6f s, clock %+.1f ppm, confidence %.2f\n",
                  c.name.c_str(),
                  c.offset_s,
                  c.drift_ppm,
                  c.sync_confidence);
    }
    std::printf("  %-12s %-10s %5dx%-5d rotate %3d  %7lld frames  %5lld dropped  %s\n",
                c.name.c_str(),
                c.serial.empty() ? "-" : c.serial.c_str(),
                c.width,
                c.height,
                c.rotate_deg,
                static_cast<long long>(c.frames),
                static_cast<long long>(c.dropped),
                c.video.c_str());
  }
  if (synced) {
    std::printf("synced by sound (clock: %s)\n", r->sync_reference.c_str());
  }
  if (!r->calibration_made.empty())
    std::printf(
        "calibration.json made: %s (`arco calibrate from-instrument` replaces it "
        "when the focal length is known)\n",
        r->calibration_made.c_str());
  for (const std::string& w : r->warnings) PrintWarning(w);
  std::printf(
      "capture of %zu cameras x %lld frames at %.6g fps -> %s (no 2D keypoints yet: run "
      "`arco detect %s`; layout %s)\n",
      r->cameras.size(),
      static_cast<long long>(r->frames),
      r->fps,
      o.output_dir.c_str(),
      o.output_dir.c_str(),
      r->layout.c_str());
  return 0;
}

struct ImportArgs {
  std::vector<std::string> cameras;
  capture::ImportKeypointsOptions options;
  void Convert() {
    options.sources.clear();
    for (const std::string& c : cameras) {
      const auto [camera, path] = SplitAssignment("--camera", c, "CAMERA=PATH");
      options.sources.push_back({camera, path});
    }
  }
};

int RunImportKeypoints(const capture::ImportKeypointsOptions& o) {
  auto r = capture::ImportKeypoints(o);
  if (!r.ok()) return PrintError(WithFlagNames(r.status().message(), kCaptureFlags));
  std::printf(
      "imported %lld frames x %lld views x %lld points (%s, layout %s): %lld detections, %lld "
      "frames without a person, %lld with several (the largest kept) -> %s\n",
      static_cast<long long>(r->frames),
      static_cast<long long>(r->views),
      static_cast<long long>(r->points),
      o.format.c_str(),
      r->layout.c_str(),
      static_cast<long long>(r->report.people_kept),
      static_cast<long long>(r->report.frames_without_person),
      static_cast<long long>(r->report.frames_with_several),
      o.capture_dir.c_str());
  for (const std::string& w : r->warnings) PrintWarning(w);
  return 0;
}

CommandRun SetupCapture(CLI::App& app) {
  auto* cmd = app.add_subcommand("capture", "Make a capture folder from videos, or fill one");
  cmd->require_subcommand(1);

  auto n = std::make_shared<CaptureNewArgs>();
  auto* create = cmd->add_subcommand(
      "new",
      "Create a capture folder that references each camera's video (or image folder, one "
      "image per frame in natural order), with a copy of the calibration; checks cameras, "
      "sizes, frame rates and frame counts. 2D keypoints come next: `arco detect CAPTURE`");
  create->add_option("--calibration",
                     n->options.calibration,
                     "Calibration (any format; copied). Required for two or more cameras; "
                     "one camera without it gets one from its video (a phone's default "
                     "focal length, its frame the world)");
  create->add_option("--video",
                     n->videos,
                     "CAMERA=FILE: a camera's video file (or single image); CAMERA is a "
                     "calibration camera's name or serial; repeat for each camera");
  create->add_option(
      "--images",
      n->images,
      "CAMERA=DIR: a camera's folder of images, one per frame (natural order); views: "
      "the --video cameras first, then these");
  create->add_option("--audio",
                     n->options.audio,
                     "Audio file of the performance (referenced); with --sync audio, the "
                     "recorder every camera is aligned to");
  create
      ->add_option("--sync",
                   n->sync,
                   "none: the cameras are synchronised (a trigger: frame g is one instant); "
                   "audio: find each camera's start and clock drift from its sound (GCC-PHAT "
                   "of the videos' audio tracks, and of --audio if given), recorded as "
                   "cameras[].offset_s and drift_ppm")
      ->check(CLI::IsMember({"none", "audio"}))
      ->capture_default_str();
  AddNumber(create,
            "--sync-max-seconds",
            n->options.sync_max_seconds,
            "With --sync audio: align at most this much of each recording, seconds",
            Closed(1, 86400))
      ->capture_default_str();
  create
      ->add_option("--instrument",
                   n->options.instrument,
                   "Instrument played (sets the keypoint layout: coco_wholebody_133 for none)")
      ->check(CLI::IsMember({"none", "cello", "violin", "viola", "double_bass"}))
      ->capture_default_str();
  AddNumber(create,
            "--fps",
            n->options.fps,
            "Frame rate of image folders, frames per second (a video's comes from its "
            "container and must agree); 0 = from the videos",
            Closed(0, kVideoFpsRange.max))
      ->capture_default_str();
  create->add_option("--rotate",
                     n->rotate,
                     "CAMERA=DEG: clockwise rotation (90, 180, 270) of the decoded frames to the "
                     "calibration's image (SPD: 90); default: the container's display rotation");
  create->add_option("--dropped-frames",
                     n->drops,
                     "CAMERA=LIST: global frames (from 1, comma-separated) the camera did not "
                     "record; its video has that many frames fewer");
  create->add_option("--spd-summary",
                     n->options.spd_summary,
                     "SPD SESSION_summary.json: dropped frames of every camera (FrameDropIDLog)");
  create->add_option("--name", n->options.name, "Session name (default: the output folder's name)");
  create
      ->add_option("-o,--output",
                   n->options.output_dir,
                   "Capture folder to create (must not exist, unless "
                   "--overwrite)")
      ->required();
  create->add_flag("--overwrite", n->options.overwrite, "Replace an existing capture folder");
  create->parse_complete_callback([n] {
    n->Convert();
    const Status valid = n->options.Validate();
    if (!valid.ok()) throw CLI::ValidationError(WithFlagNames(valid.message(), kCaptureFlags));
  });

  auto k = std::make_shared<ImportArgs>();
  auto* import = cmd->add_subcommand(
      "import-keypoints",
      "Write another detector's 2D keypoints into a capture (keypoints2d.npy and capture.json "
      "together): MMPose/RTMPose/DWPose COCO-WholeBody JSON or OpenPose JSON");
  import->add_option("capture", k->options.capture_dir, "Capture folder")->required();
  import
      ->add_option("--format",
                   k->options.format,
                   "mmpose: COCO-WholeBody (one JSON per video or a folder of per-frame "
                   "JSON); openpose: a folder of *_keypoints.json (BODY_25 + hands)")
      ->check(CLI::IsMember({"mmpose", "openpose"}))
      ->required();
  import
      ->add_option("--camera",
                   k->cameras,
                   "CAMERA=PATH: a camera's keypoint file or folder; one for every camera")
      ->required();
  import
      ->add_option("--pixels",
                   k->options.pixels,
                   "Needed when a camera has a rotation: decoded (the detector saw the video's "
                   "frames as stored; arco turns the points by the camera's rotate_deg) or "
                   "calibration (it saw them turned, e.g. SPD's images or OpenCV's "
                   "auto-rotated phone video)")
      ->check(CLI::IsMember({"decoded", "calibration"}));
  import->add_flag(
      "--overwrite", k->options.overwrite, "Replace the 2D keypoints the capture already has");
  import->parse_complete_callback([k] {
    k->Convert();
  const Status valid = k->options.Validate();
  if (!valid.ok()) throw CLI::ValidationError(WithFlagNames(valid.message(), kCaptureFlags));
});

auto paths = [create, n, import, k] {
  PathRoles roles;
  if (create->parsed()) {
    roles.AddInput("--calibration", n->options.calibration);
    for (const std::string& v : n->videos) roles.AddInput("--video", AssignedPath(v));
    for (const std::string& v : n->images) roles.AddInput("--images", AssignedPath(v));
    roles.AddInput("--audio", n->options.audio);
    roles.AddInput("--spd-summary", n->options.spd_summary);
    roles.AddOutput("-o", n->options.output_dir);
  }
  if (import->parsed()) {
    // The capture is the command's own: its keypoints and manifest are written in place.
    const std::string& capture = k->options.capture_dir;
    roles.AddOwnedFolder("CAPTURE", capture);
    for (const std::string& c : k->cameras) roles.AddInput("--camera", AssignedPath(c));
    auto manifest = ReadCaptureManifest(capture);
    const std::string keypoints =
        manifest.ok() && !manifest->keypoints2d.empty() ? manifest->keypoints2d : "keypoints2d.npy";
    roles.AddOutput("CAPTURE", ResolveCapturePath(capture, keypoints));
    roles.AddOutput("CAPTURE", ResolveCapturePath(capture, "capture.json"));
  }
  return roles;
};
return CommandRun(
    [create, n, import, k]() {
      if (create->parsed()) return RunCaptureNew(n->options);
      if (import->parsed()) return RunImportKeypoints(k->options);
      return PrintError("capture: give a subcommand (new, import-keypoints)");
    },
    paths);
}  // namespace

}  // namespace arco::cli
ARCO_REGISTER_COMMAND(capture, 18, SetupCapture);
}  // namespace arco::cli
