// labelme (https://github.com/wkentaro/labelme) annotation files: point shapes by
// label; other shapes (rectangles, polygons, ...) are ignored.
//
// labelme stores Qt image coordinates, whose origin is the top-left CORNER of the
// top-left pixel (its centre is (0.5, 0.5)). arco uses OpenCV's convention (origin at
// that pixel's centre), so the reader subtracts 0.5 unless told the file already
// uses centre coordinates.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "arco/util/status.h"

namespace arco {

enum class PixelOrigin { kCorner, kCenter };

struct LabeledPoint {
  std::string label;
  Eigen::Vector2d pixel;  // OpenCV convention
};

struct LabelmeAnnotation {
  std::string image_path;            // "imagePath", may be empty
  int image_width = 0;               // "imageWidth"; 0 when absent
  int image_height = 0;              // "imageHeight"; 0 when absent
  std::vector<LabeledPoint> points;  // in file order
  // Index of a label, -1 when absent.
  int Find(const std::string& label) const;
};

// Errors (naming `source`): malformed JSON, no "shapes" array, a point shape without
// exactly one finite [x, y] (NaN coordinates included), a label used twice, a
// non-positive image size.
StatusOr<LabelmeAnnotation> ParseLabelme(const std::string& text,
                                         const std::string& source,
                                         PixelOrigin file_origin = PixelOrigin::kCorner);
StatusOr<LabelmeAnnotation> ReadLabelme(const std::string& path,
                                        PixelOrigin file_origin = PixelOrigin::kCorner);

}  // namespace arco
