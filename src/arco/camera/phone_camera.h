// A phone's main camera when nothing better is known (docs/calibration.md "Calibrating
// from the instrument", docs/phones.md): used by `arco calibrate from-instrument` and by
// `arco capture new` for one video without a calibration.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>

#include "arco/camera/camera.h"

namespace arco {

// A 26 mm-equivalent lens on a 4:3 sensor, whose width a video keeps: 67 degrees across
// the image's longer side (2 atan(36 / (2 x 26)) = 69 degrees on 3:2, 67 on 4:3).
inline constexpr double kPhoneFovDeg = 67.0;

// fx = fy (px) of an image of this size whose longer side spans `fov_deg`.
inline double FocalPxFromFov(int width, int height, double fov_deg) {
  return 0.5 * std::max(width, height) / std::tan(0.5 * fov_deg * M_PI / 180);
}

// A camera of this image size with fx = fy = focal_px, the principal point at the image
// centre ((w - 1) / 2: pixel centres at integers, camera.h), no distortion, and its
// frame the world's.
inline Camera CentredPinhole(const std::string& name, int width, int height, double focal_px) {
  Camera cam;
  cam.name = name;
  cam.width = width;
  cam.height = height;
  cam.fx = cam.fy = focal_px;
  cam.cx = 0.5 * (width - 1);
  cam.cy = 0.5 * (height - 1);
  return cam;
}

}  // namespace arco
