#include "arco/pipeline/capture_checks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "arco/audio/audio_reader.h"
#include "arco/calibration/calibration_file.h"
#include "arco/util/file_io.h"

namespace arco::pipeline {
namespace {

namespace fs = std::filesystem;

// Samples decoded to prove the audio decodes (a fraction of a second at any rate).
constexpr int64_t kProbeSamples = 4096;

std::string Seconds(double s) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.6g", s);
  return buffer;
}

std::string ManifestPath(const std::string& capture_dir) {
  return JoinPath(capture_dir, kCaptureManifestName);
}

// `path` (named by capture.json's `field`) exists and is a file.
Status CheckInputFile(const std::string& capture_dir,
                      const std::string& field,
                      const std::string& entry,
                      const std::string& path) {
  std::error_code ec;
  const std::string where = ManifestPath(capture_dir) + ": " + field + " \"" + entry + "\"";
  if (!fs::exists(path, ec)) return Status::Error(where + ": " + path + " not found");
  if (fs::is_directory(path, ec)) return Status::Error(where + ": " + path + " is a folder");
  return Status::Ok();
}

}  // namespace

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
      return Status::Error(ManifestPath(capture_dir) + ": camera \"" + cam.name + "\" is not in " +
                           calibration_path);
    }
    view_to_camera.push_back(c);
  }
  return view_to_camera;
}

Status CheckCaptureCalibration(const std::string& capture_dir, const CaptureManifest& manifest) {
  CaptureContext capture;
  capture.capture_dir = capture_dir;
  capture.manifest = manifest;
  return LoadCaptureCalibration(&capture);
}

Status LoadCaptureCalibration(CaptureContext* capture) {
  const std::string& capture_dir = capture->capture_dir;
  const CaptureManifest& manifest = capture->manifest;
  const std::string path = ResolveCapturePath(capture_dir, manifest.calibration);
  ARCO_RETURN_IF_ERROR(CheckInputFile(capture_dir, "calibration", manifest.calibration, path));
  // Read once: parsed here, and its fingerprint taken of the same bytes.
  StatusOr<std::string> text = ReadFileToString(path);
  StatusOr<Calibration> calibration =
      text.ok() ? ParseCalibration(*text, path) : StatusOr<Calibration>(text.status());
  if (!calibration.ok()) {
    return calibration.status().WithContext(ManifestPath(capture_dir) + ": calibration");
  }
  ARCO_ASSIGN_OR_RETURN(capture->view_to_camera,
                        MatchCaptureCameras(capture_dir, manifest, calibration->rig, path));
  capture->calibration = std::move(calibration).value();
  capture->inputs[kCalibrationInput] = {manifest.calibration, FingerprintBytes(*text)};
  return Status::Ok();
}

StatusOr<CaptureAudioCheck> CheckCaptureAudio(const std::string& capture_dir,
                                              const CaptureManifest& manifest) {
  CaptureContext capture;
  capture.capture_dir = capture_dir;
  capture.manifest = manifest;
  return CheckCaptureAudio(capture);
}

StatusOr<CaptureAudioCheck> CheckCaptureAudio(const CaptureContext& capture) {
  const std::string& capture_dir = capture.capture_dir;
  const CaptureManifest& manifest = capture.manifest;
  CaptureAudioCheck check;
  if (manifest.audio.empty()) return check;
  const std::string where = ManifestPath(capture_dir);
  check.path = ResolveCapturePath(capture_dir, manifest.audio);
  ARCO_RETURN_IF_ERROR(CheckInputFile(capture_dir, "audio.file", manifest.audio, check.path));
  auto opened = OpenCaptureAudio(capture, check.path);
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

Status CheckTriangulationFilters(const TriangulateStageOptions& options,
                                 const KeypointLayout& layout,
                                 double fps,
                                 const std::string& manifest_path) {
  for (const auto& [group, filter] : options.filters) {
    if (!layout.Group(group)) {
      std::string known;
      for (const auto& g : layout.groups) known += (known.empty() ? "" : ", ") + g.name;
      return Status::Error("filter group \"" + group + "\" is not in layout " + layout.name +
                           " (groups: " + known + ")");
    }
    const Status valid = filter.Validate(fps);
    if (!valid.ok()) {
      return Status::Error("filter " + group + "=" + FilterSpecToString(filter) + " at " +
                           Seconds(fps) + " fps (" + manifest_path + "): " + valid.message());
    }
  }
  return Status::Ok();
}

Status CheckCaptureInstrumentPoints(const CaptureContext& capture) {
  const CaptureManifest& m = capture.manifest;
  ARCO_ASSIGN_OR_RETURN(const std::shared_ptr<const NpyArray<double>> read,
                        ReadKeypoints2d(capture));
  const NpyArray<double>& k = *read;
  const InstrumentModel& model = *capture.instrument;
  std::vector<int> ends;
  for (const int i : {model.nut_l(), model.nut_r(), model.bridge_l(), model.bridge_r()}) {
    ends.push_back(capture.layout.Find(model.keypoint_names()[i]));
  }
  const int64_t frames = k.shape[0], views = k.shape[1], points = k.shape[2];
  for (int64_t f = 0; f < frames; ++f) {
    bool all = true;
    for (const int p : ends) {
      int seen = 0;
      for (int64_t v = 0; v < views && seen < 2; ++v) {
        const double* q = &k.data[static_cast<size_t>(((f * views + v) * points + p) * 3)];
        if (std::isfinite(q[0]) && std::isfinite(q[1]) && q[2] > 0) ++seen;
      }
      if (seen < 2) {
        all = false;
        break;
      }
    }
    if (all) return Status::Ok();
  }
  return Status::Error(ResolveCapturePath(capture.capture_dir, m.keypoints2d) +
                       ": no frame shows the " + m.instrument +
                       "'s nut_l, nut_r, bridge_l and bridge_r in two views each (the strings "
                       "cannot be placed); a capture made from videos gets them from `arco "
                       "track` after `arco detect`");
}

}  // namespace arco::pipeline
