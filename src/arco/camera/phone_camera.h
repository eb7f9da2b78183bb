// A phone's main camera when nothing better is known (docs/calibration.md "Calibrating
// from the instrument", docs/phones.md): used by `arco calibrate from-instrument` and by
// `arco capture new` for one video without a calibration.
#pragma once

#include <algorithm>
#include <cmath>

namespace arco {

// A 26 mm-equivalent lens on a 4:3 sensor, whose width a video keeps: 67 degrees across
// the image's longer side (2 atan(36 / (2 x 26)) = 69 degrees on 3:2, 67 on 4:3).
inline constexpr double kPhoneFovDeg = 67.0;

// fx = fy (px) of an image of this size whose longer side spans `fov_deg`.
inline double FocalPxFromFov(int width, int height, double fov_deg) {
  return 0.5 * std::max(width, height) / std::tan(0.5 * fov_deg * M_PI / 180);
}

}  // namespace arco
