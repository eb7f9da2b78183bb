// The inputs a command reads through a capture or a result folder, for its PathRoles
// (util/path_roles.h; command.h's CommandRun::paths): the folder itself and the files
// its manifest names, so that no output replaces or goes into any of them (`arco pitch
// --capture c1 -o c1/audio.wav`, `arco overlay res -o cap/cam1.mp4` over the capture's
// video). A manifest that cannot be read adds only the folder: the command reports it.
#pragma once

#include <string>

#include "arco/util/path_roles.h"

namespace arco {
struct CaptureManifest;
}

namespace arco::cli {

// The capture folder (`label`, e.g. "CAPTURE" or "--capture") and its capture.json's
// calibration, audio, 2D keypoints and each camera's video or image folder.
void AddCaptureInputs(PathRoles* roles, const std::string& label, const std::string& capture_dir);
// The same from its manifest already read (`arco run`'s opened capture: capture.json is
// read once).
void AddCaptureInputs(PathRoles* roles,
                      const std::string& label,
                      const std::string& capture_dir,
                      const CaptureManifest& manifest);

// The result folder and the capture its result.json names (with that capture's files).
void AddResultInputs(PathRoles* roles, const std::string& label, const std::string& result_dir);

// "CAMERA=PATH" (--video, --images, --view, --camera) -> PATH; the text itself without '='.
std::string AssignedPath(const std::string& assignment);

}  // namespace arco::cli
