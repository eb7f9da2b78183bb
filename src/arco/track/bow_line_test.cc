// FitStickLine: the stick's centre line midway between its two edges even when one edge
// has most of the segments; one edge alone gives a half-weight line on it.
#include "arco/track/bow_line.h"

#include <gtest/gtest.h>

#include <cmath>

namespace arco::track {
namespace {

// A segment from u0 to u1 along a line through `origin` with direction `t`, `offset`
// pixels across it.
StickSegment Along(
    const Eigen::Vector2d& origin, const Eigen::Vector2d& t, double u0, double u1, double offset) {
  const Eigen::Vector2d n(-t.y(), t.x());
  StickSegment s;
  s.a = origin + u0 * t + offset * n;
  s.b = origin + u1 * t + offset * n;
  s.length = (s.b - s.a).norm();
  return s;
}

double DistanceToLine(const Eigen::Vector2d& x,
                      const Eigen::Vector2d& point,
                      const Eigen::Vector2d& direction) {
  return std::abs(direction.x() * (x.y() - point.y()) - direction.y() * (x.x() - point.x()));
}

TEST(FitStickLine, RunsMidwayBetweenUnevenEdges) {
  const Eigen::Vector2d origin(300, 200);
  const Eigen::Vector2d t = Eigen::Vector2d(std::cos(0.2), std::sin(0.2));
  // The upper edge (+5 px) in four pieces, the lower (-5 px) in one: 80 % against 20 %.
  std::vector<StickSegment> segments;
  for (int k = 0; k < 4; ++k) segments.push_back(Along(origin, t, 60.0 * k, 60.0 * k + 40, 5));
  segments.push_back(Along(origin, t, 100, 140, -5));
  Eigen::Vector2d point, direction;
  double weight = 0;
  ASSERT_TRUE(FitStickLine(&segments, &point, &direction, &weight));
  EXPECT_EQ(weight, 1.0);
  EXPECT_LT(DistanceToLine(origin, point, direction), 1e-6);
  EXPECT_LT(DistanceToLine(origin + 300 * t, point, direction), 1e-6);
  for (const StickSegment& s : segments) EXPECT_LT(s.residual_px, 1e-6);
}

TEST(FitStickLine, OneEdgeIsAHalfWeightLineOnIt) {
  const Eigen::Vector2d origin(50, 400);
  const Eigen::Vector2d t = Eigen::Vector2d(std::cos(-1.0), std::sin(-1.0));
  std::vector<StickSegment> segments;
  for (int k = 0; k < 3; ++k) segments.push_back(Along(origin, t, 50.0 * k, 50.0 * k + 30, 4));
  Eigen::Vector2d point, direction;
  double weight = 0;
  ASSERT_TRUE(FitStickLine(&segments, &point, &direction, &weight));
  EXPECT_EQ(weight, 0.5);
  const Eigen::Vector2d n(-t.y(), t.x());
  EXPECT_LT(DistanceToLine(origin + 4 * n, point, direction), 1e-6);
  EXPECT_LT(DistanceToLine(origin + 4 * n + 200 * t, point, direction), 1e-6);
}

TEST(FitStickLine, NoSegmentsNoLine) {
  std::vector<StickSegment> segments;
  Eigen::Vector2d point, direction;
  double weight = 1;
  EXPECT_FALSE(FitStickLine(&segments, &point, &direction, &weight));
  EXPECT_EQ(weight, 0.0);
}

}  // namespace
}  // namespace arco::track
