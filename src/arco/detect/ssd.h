// Decoding of MediaPipe's SSD detectors (pose_detection): anchors, boxes and keypoints
// relative to them, score sigmoid, and weighted non-maximum suppression, as MediaPipe's
// SsdAnchorsCalculator, TensorsToDetectionsCalculator and NonMaxSuppressionCalculator
// (WEIGHTED) define them for pose_detection (pose_detection_cpu.pbtxt).
//
// Coordinates here are normalised to the detector's square input (0..1, x right, y
// down, roi.h's crop convention); the caller maps them to the image through the ROI the
// input was cut from.
#pragma once

#include <vector>

#include "arco/detect/roi.h"

namespace arco::detect {

// Anchor centres of a fixed-anchor-size SSD (every anchor's width and height is 1):
// for each stride, a grid of ceil(input / stride) cells, rows then columns, with
// `per_cell` anchors at each cell centre ((x + 0.5) / grid).
struct SsdLayer {
  int stride = 0;
  int anchors_per_cell = 0;
};
std::vector<Point2> SsdAnchors(int input_size, const std::vector<SsdLayer>& layers);
// pose_detection's: 224 input, strides 8, 16, 32 with 2, 2, 6 anchors per cell (2254).
const std::vector<Point2>& PoseDetectionAnchors();
constexpr int kPoseDetectionInputSize = 224;
constexpr int kPoseDetectionKeypoints = 4;

// One detection: a box and keypoints, normalised to the detector's input.
struct SsdDetection {
  double score = 0;  // sigmoid of the logit, [0, 1]
  double x_min = 0, y_min = 0, width = 0, height = 0;
  std::vector<Point2> keypoints;
};

// Boxes [num_anchors x (4 + 2 * num_keypoints)] as (cx, cy, w, h, kx0, ky0, ...) in input
// pixels relative to the anchor centre, scores [num_anchors] logits (clipped to +-100
// before the sigmoid). Returns the detections scoring at least min_score, in anchor
// order. Throws std::invalid_argument on inconsistent sizes.
std::vector<SsdDetection> DecodeSsd(const float* boxes,
                                    const float* scores,
                                    const std::vector<Point2>& anchors,
                                    int num_keypoints,
                                    int input_size,
                                    double min_score);

double IntersectionOverUnion(const SsdDetection& a, const SsdDetection& b);

// MediaPipe's weighted NMS: repeatedly take the best remaining detection (highest
// score, lowest index on ties), average the box and keypoints of every remaining one
// overlapping it with IoU > min_iou, weighted by score, keep the best one's score,
// and drop them. Best first. Sequential and order-defined: deterministic.
std::vector<SsdDetection> WeightedNonMaxSuppression(std::vector<SsdDetection> detections,
                                                    double min_iou);

}  // namespace arco::detect
