#include "arco/detect/roi.h"

#include <algorithm>
#include <cmath>

namespace arco::detect {
namespace {

constexpr double kPi = 3.14159265358979323846;

double WrapAngle(double angle) { return angle - 2 * kPi * std::floor((angle + kPi) / (2 * kPi)); }

}  // namespace

Point2 Roi::ToImage(double u, double v) const {
  const double c = std::cos(rotation_rad), s = std::sin(rotation_rad);
  const double x = (u - 0.5) * side_px, y = (v - 0.5) * side_px;
  return {centre.x + c * x - s * y, centre.y + s * x + c * y};
}

void Roi::CropPixelToImageAffine(int input_size, double m[6]) const {
  // Crop pixel u has normalised coordinate (u + 0.5) / N: image = origin + u * step_x +
  // v * step_y with steps of side / N along the crop's axes.
  const double c = std::cos(rotation_rad), s = std::sin(rotation_rad);
  const double step = side_px / input_size;
  const Point2 origin = ToImage(0.5 / input_size, 0.5 / input_size);
  m[0] = step * c;
  m[1] = -step * s;
  m[2] = origin.x;
  m[3] = step * s;
  m[4] = step * c;
  m[5] = origin.y;
}

double AlignmentRotation(Point2 from, Point2 to, double target_angle_rad) {
  return WrapAngle(target_angle_rad - std::atan2(-(to.y - from.y), to.x - from.x));
}

Roi RoiFromAlignmentPoints(
    Point2 centre, Point2 scale_point, double target_angle_rad, double scale, double shift_y) {
  Roi roi;
  roi.rotation_rad = AlignmentRotation(centre, scale_point, target_angle_rad);
  const double side = 2.0 * Norm(scale_point - centre);
  roi.side_px = side * scale;
  // As RectTransformationCalculator: the shift is a fraction of the side before scaling,
  // along the crop's y axis, which is (-sin r, cos r) in the image.
  const double shift = shift_y * side;
  roi.centre = {centre.x - std::sin(roi.rotation_rad) * shift,
                centre.y + std::cos(roi.rotation_rad) * shift};
  return roi;
}

Roi WholeImageRoi(int width, int height) {
  Roi roi;
  roi.centre = {(width - 1) / 2.0, (height - 1) / 2.0};
  roi.side_px = width > height ? width : height;
  return roi;
}

Roi HandRoiFromPose(Point2 wrist, Point2 index, Point2 pinky, double scale, double shift_y) {
  const Point2 middle = (1.0 / 3.0) * (2.0 * index + pinky);
  return RoiFromAlignmentPoints(middle, middle + (middle - wrist), kPi / 2, scale, shift_y);
}

// hand_landmark_landmarks_to_roi.pbtxt's SplitNormalizedLandmarkListCalculator ranges
// [0, 4), [5, 7), [9, 11), [13, 15), [17, 19).
const bool kHandTrackingRoiPoints[21] = {true,  true,  true,  true, false, true,  true,
                                         false, false, true,  true, false, false, true,
                                         true,  false, false, true, true,  false, false};

std::optional<Roi> HandRoiFromLandmarks(const Point2* points, const bool* use) {
  constexpr int kWrist = 0, kIndexBase = 5, kMiddleBase = 9, kRingBase = 13;
  const auto used = [&](int i) { return use == nullptr || use[i]; };
  if (!used(kWrist) || !used(kIndexBase) || !used(kMiddleBase) || !used(kRingBase)) {
    return std::nullopt;
  }
  const Point2 bases = 0.5 * (0.5 * (points[kIndexBase] + points[kRingBase]) + points[kMiddleBase]);
  const double rotation = AlignmentRotation(points[kWrist], bases, kPi / 2);
  // The crop's axes in the image: x along (cos r, sin r), y along (-sin r, cos r).
  const double c = std::cos(rotation), s = std::sin(rotation);
  double lo_x = INFINITY, lo_y = INFINITY, hi_x = -INFINITY, hi_y = -INFINITY;
  for (int i = 0; i < 21; ++i) {
    if (!used(i)) continue;
    const double qx = points[i].x * c + points[i].y * s;
    const double qy = points[i].x * -s + points[i].y * c;
    lo_x = std::min(lo_x, qx);
    lo_y = std::min(lo_y, qy);
    hi_x = std::max(hi_x, qx);
    hi_y = std::max(hi_y, qy);
  }
  const double mid_x = 0.5 * (lo_x + hi_x), mid_y = 0.5 * (lo_y + hi_y);
  const double side = kHandLandmarksRoiScale * std::max(hi_x - lo_x, hi_y - lo_y);
  if (!(side > 0) || !std::isfinite(side)) return std::nullopt;
  Roi roi;
  const double shift = kHandLandmarksRoiShiftY * side;
  roi.centre = {mid_x * c + mid_y * -s + shift * -s, mid_x * s + mid_y * c + shift * c};
  roi.side_px = side;
  roi.rotation_rad = rotation;
  return roi;
}

}  // namespace arco::detect
