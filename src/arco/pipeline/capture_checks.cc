#include "arco/pipeline/capture_checks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "arco/calibration/calibration_file.h"
#include "arco/capture/capture_checks.h"
#include "arco/util/file_io.h"

namespace arco::pipeline {
namespace {

namespace fs = std::filesystem;

std::string Seconds(double s) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.6g", s);
  return buffer;
}

}  // namespace

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
  ARCO_RETURN_IF_ERROR(
      capture::CheckCaptureInputFile(capture_dir, "calibration", manifest.calibration, path));
  // Read once: parsed here, and its fingerprint taken of the same bytes.
  StatusOr<std::string> text = ReadFileToString(path);
  StatusOr<Calibration> calibration =
      text.ok() ? calibration::ParseCalibration(*text, path) : StatusOr<Calibration>(text.status());
  if (!calibration.ok()) {
    return calibration.status().WithContext(CaptureManifestPath(capture_dir) + ": calibration");
  }
  ARCO_ASSIGN_OR_RETURN(
      capture->view_to_camera,
      capture::MatchCaptureCameras(capture_dir, manifest, calibration->rig, path));
  capture->calibration = std::move(calibration).value();
  capture->inputs[kCalibrationInput] = {manifest.calibration, FingerprintBytes(*text)};
  return Status::Ok();
}

StatusOr<capture::CaptureAudioCheck> CheckCaptureAudio(const CaptureContext& capture) {
  return capture::CheckCaptureAudio(
      capture.capture_dir, capture.manifest, [&capture](const std::string& path) {
        return OpenCaptureAudio(capture, path);
      });
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
  // Two views place a point; one camera places the instrument by PnP from its one view.
  const int needed = views == 1 ? 1 : 2;
  for (int64_t f = 0; f < frames; ++f) {
    bool all = true;
    for (const int p : ends) {
      int seen = 0;
      for (int64_t v = 0; v < views && seen < needed; ++v) {
        const double* q = &k.data[static_cast<size_t>(((f * views + v) * points + p) * 3)];
        if (std::isfinite(q[0]) && std::isfinite(q[1]) && q[2] > 0) ++seen;
      }
      if (seen < needed) {
        all = false;
        break;
      }
    }
    if (all) return Status::Ok();
  }
  return Status::Error(ResolveCapturePath(capture.capture_dir, m.keypoints2d) +
                       ": no frame shows the " + m.instrument +
                       "'s nut_l, nut_r, bridge_l and bridge_r in " +
                       (views == 1 ? "its view" : "two views each") +
                       " (the strings "
                       "cannot be placed); a capture made from videos gets them from `arco "
                       "track` after `arco detect`");
}

}  // namespace arco::pipeline
