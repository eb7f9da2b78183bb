#include "arco/pipeline/capture_inputs.h"

namespace arco::pipeline {

StatusOr<CaptureInputs> FingerprintCaptureInputs(const std::string& capture_dir,
                                                 const CaptureManifest& manifest,
                                                 std::initializer_list<const char*> roles) {
  CaptureInputs out;
  for (const std::string role : roles) {
    std::string file;
    if (role == kManifestInput) file = kCaptureManifestName;
    if (role == kCalibrationInput) file = manifest.calibration;
    if (role == kKeypoints2dInput) file = manifest.keypoints2d;
    if (role == kAudioInput) file = manifest.audio;
    if (file.empty()) continue;  // not in this capture
    ARCO_ASSIGN_OR_RETURN(Fingerprint f, FingerprintFile(ResolveCapturePath(capture_dir, file)));
    out[role] = {file, std::move(f)};
  }
  return out;
}

CaptureInputs SelectInputs(const CaptureInputs& inputs, std::initializer_list<const char*> roles) {
  CaptureInputs out;
  for (const char* role : roles) {
    auto it = inputs.find(role);
    if (it != inputs.end()) out.insert(*it);
  }
  return out;
}

}  // namespace arco::pipeline
