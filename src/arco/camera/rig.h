// A calibrated multi-camera rig: the cameras and the unit of world coordinates.
#pragma once

#include <string>
#include <vector>

#include "arco/camera/camera.h"

namespace arco {

struct Rig {
  std::vector<Camera> cameras;
  // Unit of world coordinates and translations: "mm", "m", or "metashape"
  // (arbitrary chunk units; a metric scale must come from elsewhere).
  std::string units = "unknown";
  // Index of the camera whose name or serial equals `id`; -1 when absent.
  int FindCamera(const std::string& id) const;
};

}  // namespace arco
