// Rotated square regions of interest (ROIs) in an image, as MediaPipe's graphs use them
// to cut the crops the landmark networks see, and the geometry that derives them from
// two alignment points.
//
// Conventions. Image points are pixels in OpenCV's convention: the origin is the centre
// of the top-left pixel, x right, y down. A crop's own coordinates are normalised:
// (0, 0) is the crop's top-left corner, (1, 1) its bottom-right corner, so crop pixel
// (u, v) of an N x N crop has its centre at ((u + 0.5) / N, (v + 0.5) / N), and a
// network output in crop pixels p maps to p / N. `rotation_rad` is MediaPipe's: the
// crop's x axis points along (cos r, sin r) in the image and its y axis (down) along
// (-sin r, cos r); r = 0 is an upright crop, r > 0 turns it clockwise on screen.
#pragma once

#include <cmath>
#include <optional>

namespace arco::detect {

struct Point2 {
  double x = 0, y = 0;
};
inline Point2 operator+(Point2 a, Point2 b) { return {a.x + b.x, a.y + b.y}; }
inline Point2 operator-(Point2 a, Point2 b) { return {a.x - b.x, a.y - b.y}; }
inline Point2 operator*(double s, Point2 a) { return {s * a.x, s * a.y}; }
inline double Norm(Point2 a) { return std::hypot(a.x, a.y); }

struct Roi {
  Point2 centre;       // image pixels
  double side_px = 0;  // the square's side, image pixels
  double rotation_rad = 0;

  // The image point of normalised crop coordinates (u, v) in [0, 1] x [0, 1].
  Point2 ToImage(double u, double v) const;
  // The image point of network output `p_crop` (crop pixels of an input_size crop).
  Point2 CropPixelToImage(double x_crop, double y_crop, int input_size) const {
    return ToImage(x_crop / input_size, y_crop / input_size);
  }
  // The affine map from crop pixel indices (u, v) of an input_size x input_size crop
  // to image points: image = [a b c; d e f] * (u, v, 1), row-major in `m`.
  void CropPixelToImageAffine(int input_size, double m[6]) const;
  bool IsFinite() const {
    return std::isfinite(centre.x) && std::isfinite(centre.y) && std::isfinite(side_px) &&
           std::isfinite(rotation_rad);
  }
};

// MediaPipe's rotation of a crop whose `from` -> `to` vector should point at
// `target_angle_rad` (counter-clockwise from the image x axis, y up: pi / 2 is "up"):
// target - atan2(-(to.y - from.y), to.x - from.x), wrapped to [-pi, pi).
double AlignmentRotation(Point2 from, Point2 to, double target_angle_rad);

// MediaPipe's AlignmentPointsRectsCalculator followed by RectTransformationCalculator
// (square_long): the square centred on `centre` with side 2 |scale_point - centre|,
// turned so centre -> scale_point points at target_angle_rad, moved by shift_y * side
// along the crop's own y axis (negative: towards its top), then scaled by `scale`.
Roi RoiFromAlignmentPoints(
    Point2 centre, Point2 scale_point, double target_angle_rad, double scale, double shift_y = 0);

// The whole image letterboxed into a square (MediaPipe's keep_aspect_ratio with zero
// borders): centred, side = the longer image side, upright.
Roi WholeImageRoi(int width, int height);

// MediaPipe Holistic's hand ROI from the pose's wrist, index and little-finger points
// (HandDetectionsFromPoseToRectsCalculator): the middle finger's base estimated as
// (2 index + pinky) / 3, a square of side 2 |middle - wrist| centred on it, turned so
// wrist -> middle points up; then shifted by shift_y * side and scaled by `scale`.
Roi HandRoiFromPose(Point2 wrist, Point2 index, Point2 pinky, double scale, double shift_y);

// MediaPipe's crop around a hand from its own landmarks (hand_landmark_landmarks_to_roi:
// HandLandmarksToRectCalculator, then RectTransformationCalculator with scale 2, shift_y
// -0.1, square_long): turned so the wrist -> the finger bases' centre
// ((index + ring) / 2 + middle) / 2 points up, the bounding box of the points in that
// frame, its longer side x kHandLandmarksRoiScale, moved kHandLandmarksRoiShiftY x side
// along the crop's y axis (towards the fingers). `points` holds the 21 points in hand_21
// order; points whose `use` is false are left out of the box (nullptr: all are used).
// Empty when the wrist or the index, middle or ring base is left out, or the box is empty.
inline constexpr double kHandLandmarksRoiScale = 2.0;
inline constexpr double kHandLandmarksRoiShiftY = -0.1;
std::optional<Roi> HandRoiFromLandmarks(const Point2* points, const bool* use = nullptr);

// The hand_21 points MediaPipe's hand tracking graph takes for the next frame's crop:
// the wrist, the thumb's first three and every finger's base and next joint (the
// fingertips and the last joints are left out: they move the most between frames).
extern const bool kHandTrackingRoiPoints[21];

}  // namespace arco::detect
