#include "arco/pipeline/capture_context.h"

#include <filesystem>
#include <stdexcept>

#include "arco/hand/hand_model.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/util/file_io.h"

namespace arco::pipeline {
namespace {

constexpr int kLeftHandFirst = wholebody::kLeftHandFirst;

}  // namespace

void ReadCaptureAudioBytes(CaptureContext* capture) {
  if (capture->manifest.audio.empty()) return;
  const std::string path = ResolveCapturePath(capture->capture_dir, capture->manifest.audio);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return;
  const uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec || size == 0 || size > static_cast<uintmax_t>(kMaxAudioInMemoryBytes)) return;
  StatusOr<std::string> bytes = ReadFileToString(path);
  if (bytes.ok()) capture->audio_bytes = std::make_shared<const std::string>(*std::move(bytes));
}

StatusOr<std::unique_ptr<audio::AudioReader>> OpenCaptureAudio(const CaptureContext& capture,
                                                               const std::string& path) {
  if (capture.audio_bytes) {
    auto reader = audio::OpenAudioFromMemory(capture.audio_bytes.get(), path);
    if (reader.ok()) return reader;
  }
  return audio::OpenAudio(path);
}

StatusOr<CaptureContext> OpenCapture(const std::string& capture_dir) {
  CaptureContext c;
  c.capture_dir = capture_dir;
  const std::string where = CaptureManifestPath(capture_dir);
  // Read once: parsed here, and its fingerprint taken of the same bytes.
  ARCO_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(where));
  ARCO_ASSIGN_OR_RETURN(c.manifest, ParseCaptureManifest(text, where));
  c.inputs[kManifestInput] = {kCaptureManifestName, FingerprintBytes(text)};
  ARCO_RETURN_IF_ERROR(CheckCaptureHasKeypoints2d(capture_dir, c.manifest));
  ARCO_ASSIGN_OR_RETURN(c.layout, c.manifest.Layout());
  if (c.manifest.instrument == "none" || c.manifest.instrument.empty()) {
    return Status::Error(where + ": the capture names no instrument; arco run needs one");
  }
  ARCO_ASSIGN_OR_RETURN(InstrumentKind kind, ParseInstrumentKind(c.manifest.instrument));
  InstrumentOptions io;
  io.kind = kind;
  io.tuning.a4_hz = c.manifest.tuning_a4_hz;
  StatusOr<InstrumentModel> model = InstrumentModel::Create(io);
  if (!model.ok()) return model.status().WithContext(where);
  c.instrument = std::make_shared<const InstrumentModel>(std::move(model).value());
  for (const std::string& name : c.instrument->keypoint_names()) {
    if (c.layout.Find(name) < 0) {
      return Status::Error(where + ": layout " + c.layout.name + " has no instrument point " +
                           name);
    }
  }
  if (c.layout.size() < kLeftHandFirst + hand::kNumHandKeypoints) {
    return Status::Error(where + ": layout " + c.layout.name + " has no whole-body hands");
  }
  return c;
}

NpyArray<double> PointsInMm(const NpyArray<double>& points_in_world, double world_units_per_mm) {
  NpyArray<double> mm = points_in_world;
  for (double& v : mm.data) v /= world_units_per_mm;
  return mm;
}

std::vector<Camera> ViewCamerasInMm(const CaptureContext& capture, double world_units_per_mm) {
  if (capture.view_to_camera.size() != capture.manifest.cameras.size()) {
    throw std::invalid_argument("ViewCamerasInMm: the capture's calibration is not loaded");
  }
  std::vector<Camera> cameras;
  for (const int c : capture.view_to_camera) {
    Camera camera = capture.calibration.rig.cameras.at(static_cast<size_t>(c));
    camera.cam_from_world.translation /= world_units_per_mm;
    cameras.push_back(camera);
  }
  return cameras;
}

Status LoadCaptureKeypoints2d(CaptureContext* capture) {
  const CaptureManifest& m = capture->manifest;
  ARCO_ASSIGN_OR_RETURN(const FileBytes bytes,
                        ReadCaptureKeypoints2dBytes(capture->capture_dir, m));
  ARCO_ASSIGN_OR_RETURN(NpyArray<double> k,
                        ParseCaptureKeypoints2d(bytes.view(), capture->capture_dir, m));
  capture->keypoints2d = std::make_shared<const NpyArray<double>>(std::move(k));
  capture->inputs[kKeypoints2dInput] = {m.keypoints2d, FingerprintBytes(bytes.view())};
  return Status::Ok();
}

StatusOr<std::shared_ptr<const NpyArray<double>>> ReadKeypoints2d(const CaptureContext& capture) {
  if (capture.keypoints2d) return capture.keypoints2d;
  ARCO_ASSIGN_OR_RETURN(NpyArray<double> k,
                        ReadCaptureKeypoints2d(capture.capture_dir, capture.manifest));
  return std::make_shared<const NpyArray<double>>(std::move(k));
}

}  // namespace arco::pipeline
