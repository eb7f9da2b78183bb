#include "arco/cli/command_paths.h"

#include "arco/mocap/capture.h"
#include "arco/pipeline/result_folder.h"

namespace arco::cli {

void AddCaptureInputs(PathRoles* roles, const std::string& label, const std::string& capture_dir) {
  if (capture_dir.empty()) return;
  auto manifest = ReadCaptureManifest(capture_dir);
  if (!manifest.ok()) {
    roles->AddInput(label, capture_dir);
    return;
  }
  AddCaptureInputs(roles, label, capture_dir, *manifest);
}

void AddCaptureInputs(PathRoles* roles,
                      const std::string& label,
                      const std::string& capture_dir,
                      const CaptureManifest& manifest) {
  if (capture_dir.empty()) return;
  roles->AddInput(label, capture_dir);
  const auto add = [&](const std::string& what, const std::string& entry) {
    if (!entry.empty()) {
      roles->AddInput("the " + what + " of " + label, ResolveCapturePath(capture_dir, entry));
    }
  };
  add("calibration", manifest.calibration);
  add("audio", manifest.audio);
  add("2D keypoints", manifest.keypoints2d);
  for (const CaptureCamera& camera : manifest.cameras) {
    add("video of camera " + camera.name, camera.video);
  }
}

void AddResultInputs(PathRoles* roles, const std::string& label, const std::string& result_dir) {
  if (result_dir.empty()) return;
  roles->AddInput(label, result_dir);
  auto header = pipeline::ResultFolder(result_dir).ReadHeader(pipeline::InputCheck::kSkip);
  if (header.ok()) AddCaptureInputs(roles, "the capture of " + label, header->capture_dir);
}

std::string AssignedPath(const std::string& assignment) {
  const size_t eq = assignment.find('=');
  return eq == std::string::npos ? assignment : assignment.substr(eq + 1);
}

}  // namespace arco::cli
