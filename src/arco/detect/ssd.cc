#include "arco/detect/ssd.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

namespace arco::detect {

std::vector<Point2> SsdAnchors(int input_size, const std::vector<SsdLayer>& layers) {
  std::vector<Point2> anchors;
  for (const SsdLayer& layer : layers) {
    if (layer.stride <= 0 || layer.anchors_per_cell <= 0) {
      throw std::invalid_argument("SsdAnchors: stride and anchors_per_cell must be > 0");
    }
    const int grid = (input_size + layer.stride - 1) / layer.stride;
    for (int y = 0; y < grid; ++y) {
      for (int x = 0; x < grid; ++x) {
        for (int k = 0; k < layer.anchors_per_cell; ++k) {
          anchors.push_back({(x + 0.5) / grid, (y + 0.5) / grid});
        }
      }
    }
  }
  return anchors;
}

const std::vector<Point2>& PoseDetectionAnchors() {
  static const std::vector<Point2> anchors =
      SsdAnchors(kPoseDetectionInputSize, {{8, 2}, {16, 2}, {32, 6}});
  return anchors;
}

std::vector<SsdDetection> DecodeSsd(const float* boxes,
                                    const float* scores,
                                    const std::vector<Point2>& anchors,
                                    int num_keypoints,
                                    int input_size,
                                    double min_score) {
  if (boxes == nullptr || scores == nullptr || num_keypoints < 0 || input_size <= 0) {
    throw std::invalid_argument("DecodeSsd: null tensors or a bad size");
  }
  const int stride = 4 + 2 * num_keypoints;
  std::vector<SsdDetection> detections;
  for (size_t i = 0; i < anchors.size(); ++i) {
    const double logit = std::clamp(static_cast<double>(scores[i]), -100.0, 100.0);
    const double score = 1.0 / (1.0 + std::exp(-logit));
    if (!(score >= min_score)) continue;
    const float* raw = boxes + i * stride;
    const double size = input_size;  // divide in double, not float
    SsdDetection d;
    d.score = score;
    const double cx = raw[0] / size + anchors[i].x;
    const double cy = raw[1] / size + anchors[i].y;
    d.width = raw[2] / size;
    d.height = raw[3] / size;
    d.x_min = cx - d.width / 2;
    d.y_min = cy - d.height / 2;
    d.keypoints.resize(num_keypoints);
    for (int k = 0; k < num_keypoints; ++k) {
      d.keypoints[k] = {raw[4 + 2 * k] / size + anchors[i].x, raw[5 + 2 * k] / size + anchors[i].y};
    }
    detections.push_back(std::move(d));
  }
  return detections;
}

double IntersectionOverUnion(const SsdDetection& a, const SsdDetection& b) {
  const double x0 = std::max(a.x_min, b.x_min), y0 = std::max(a.y_min, b.y_min);
  const double x1 = std::min(a.x_min + a.width, b.x_min + b.width);
  const double y1 = std::min(a.y_min + a.height, b.y_min + b.height);
  if (x1 <= x0 || y1 <= y0) return 0.0;
  const double intersection = (x1 - x0) * (y1 - y0);
  const double uni = a.width * a.height + b.width * b.height - intersection;
  return uni > 0 ? intersection / uni : 0.0;
}

std::vector<SsdDetection> WeightedNonMaxSuppression(std::vector<SsdDetection> detections,
                                                    double min_iou) {
  // Highest score first; stable, so equal scores keep anchor order.
  std::vector<size_t> order(detections.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return detections[a].score > detections[b].score;
  });
  std::vector<SsdDetection> kept;
  std::vector<bool> used(detections.size(), false);
  for (size_t oi = 0; oi < order.size(); ++oi) {
    const size_t best = order[oi];
    if (used[best]) continue;
    const SsdDetection& top = detections[best];
    SsdDetection merged = top;
    double weight = 0, x_min = 0, y_min = 0, x_max = 0, y_max = 0;
    std::vector<Point2> keypoints(top.keypoints.size());
    for (size_t oj = oi; oj < order.size(); ++oj) {
      const size_t j = order[oj];
      if (used[j]) continue;
      const SsdDetection& d = detections[j];
      if (j != best && !(IntersectionOverUnion(top, d) > min_iou)) continue;
      used[j] = true;
      weight += d.score;
      x_min += d.score * d.x_min;
      y_min += d.score * d.y_min;
      x_max += d.score * (d.x_min + d.width);
      y_max += d.score * (d.y_min + d.height);
      for (size_t k = 0; k < keypoints.size(); ++k) {
        keypoints[k] = keypoints[k] + d.score * d.keypoints[k];
      }
    }
    if (weight > 0) {
      merged.x_min = x_min / weight;
      merged.y_min = y_min / weight;
      merged.width = x_max / weight - merged.x_min;
      merged.height = y_max / weight - merged.y_min;
      for (size_t k = 0; k < keypoints.size(); ++k) {
        merged.keypoints[k] = (1.0 / weight) * keypoints[k];
      }
    }
    kept.push_back(std::move(merged));
  }
  return kept;
}

}  // namespace arco::detect
