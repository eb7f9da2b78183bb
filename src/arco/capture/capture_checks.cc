#include "arco/capture/capture_checks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "arco/audio/audio_reader.h"
#include "arco/util/file_io.h"

namespace arco::capture {
namespace {

namespace fs = std::filesystem;

// Samples decoded to prove the audio decodes (a fraction of a second at any rate).
constexpr int64_t kProbeSamples = 4096;

std::string Seconds(double s) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.6g", s);
  return buffer;
}

}  // namespace

Status CheckCaptureInputFile(const std::string& capture_dir,
                             const std::string& field,
                             const std::string& entry,
                             const std::string& path) {
  std::error_code ec;
  const std::string where = CaptureManifestPath(capture_dir) + ": " + field + " \"" + entry + "\"";
  if (!fs::exists(path, ec)) return Status::Error(where + ": " + path + " not found");
  if (fs::is_directory(path, ec)) return Status::Error(where + ": " + path + " is a folder");
  return Status::Ok();
}

StatusOr<std::vector<int>> MatchCaptureCameras(const std::string& capture_dir,
                                               const CaptureManifest& manifest,
                                               const Rig& rig,
                                               const std::string& calibration_path) {
  std::vector<int> view_to_camera;
  for (size_t v = 0; v < manifest.cameras.size(); ++v) {
    const CaptureCamera& cam = manifest.cameras[v];
    int c = rig.FindCamera(cam.name);
    if (c < 0 && !cam.serial.empty()) c = rig.FindCamera(cam.serial);
    if (c < 0) {
      return Status::Error(CaptureManifestPath(capture_dir) + ": camera \"" + cam.name +
                           "\" is not in " + calibration_path);
    }
    view_to_camera.push_back(c);
  }
  return view_to_camera;
}

StatusOr<CaptureAudioCheck> CheckCaptureAudio(const std::string& capture_dir,
                                              const CaptureManifest& manifest,
                                              const CaptureAudioOpener& open) {
  CaptureAudioCheck check;
  if (manifest.audio.empty()) return check;
  const std::string where = CaptureManifestPath(capture_dir);
  check.path = ResolveCapturePath(capture_dir, manifest.audio);
  ARCO_RETURN_IF_ERROR(
      CheckCaptureInputFile(capture_dir, "audio.file", manifest.audio, check.path));
  auto opened = open ? open(check.path) : audio::OpenAudio(check.path);
  if (!opened.ok()) return opened.status().WithContext(where + ": audio.file");
  audio::AudioReader& reader = **opened;
  check.format = reader.info().format;
  // Decoding the first samples proves the codec works; the length is the header's when it
  // has one (a short file is the pitch stage's warning), else the decoded count.
  std::vector<float> block(kProbeSamples);
  int64_t decoded = 0;
  while (true) {
    StatusOr<int64_t> got = reader.ReadMono(block.data(), kProbeSamples);
    if (!got.ok()) return got.status().WithContext(where + ": audio.file");
    decoded += *got;
    if (*got == 0 || reader.info().frames >= 0) break;
  }
  // A truncated file is as long as what it holds (its warning comes from the pitch stage).
  const int64_t frames =
      reader.info().frames >= 0 ? reader.info().frames - reader.info().missing_frames : decoded;
  if (decoded == 0 || frames == 0) {
    return Status::Error(where + ": audio.file \"" + manifest.audio + "\": " + check.path +
                         " holds no audio samples");
  }
  check.duration_s = static_cast<double>(frames) / reader.info().sample_rate_hz;
  // Video frame i is at audio time offset_s + i / fps (docs/audio.md).
  const double first_s = manifest.audio_offset_s;
  const double last_s =
      first_s + static_cast<double>(std::max<int64_t>(0, manifest.frame_count - 1)) / manifest.fps;
  const std::string span = "(0.." + Seconds(check.duration_s) + " s, " + check.path + ")";
  if (first_s >= check.duration_s) {
    return Status::Error(where + ": audio.offset_s = " + Seconds(first_s) +
                         " s is outside the audio " + span);
  }
  if (last_s < 0) {
    return Status::Error(where + ": audio.offset_s = " + Seconds(first_s) +
                         " s puts the last frame at " + Seconds(last_s) +
                         " s, before the audio starts " + span);
  }
  return check;
}

}  // namespace arco::capture
