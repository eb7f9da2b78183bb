// The bow stick's image line from LSD segments (track/bow_tracker.h, step 1). The
// segments lie on the stick's two edges, a few pixels apart: a single robust line locks
// onto whichever edge has more segments, up to half the stick's width off its centre
// (measured 5-10 px on bow_tracker_test's 10 px stick, and a bias the all-view pose then
// inherits). So: a total-least-squares line through all endpoints (weights: length)
// gives the direction; the segments' offsets across it split into two edges (the split
// with the largest between-edge variance, Otsu, IEEE SMC 1979, on the length-weighted
// offsets); with two edges >= 2 px apart, each holding >= 15 % of the length, the line
// runs midway between their weighted-median offsets (weight 1), and the direction is
// refitted with each edge moved onto it (six passes); otherwise (one edge seen, or a
// stick too thin to split) the line runs through the weighted-median offset (weight
// 0.5: it may be an edge, half a width off).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace arco::track {

// A line segment in a view, in ideal (undistorted) pixels.
struct StickSegment {
  Eigen::Vector2d a = Eigen::Vector2d::Zero(), b = Eigen::Vector2d::Zero();
  double length = 0;
  double residual_px = 0;  // set by FitStickLine: RMS distance of a and b to its edge
};

// The stick's centre line (a point and a unit direction, ideal pixels) and its weight
// for the all-view pose (1: between two edges, 0.5: one line). False, weight 0, without
// segments. Sets each segment's residual_px.
bool FitStickLine(std::vector<StickSegment>* segments,
                  Eigen::Vector2d* point,
                  Eigen::Vector2d* direction,
                  double* weight);

}  // namespace arco::track
