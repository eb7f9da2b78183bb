#include "arco/track/bow_line.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <utility>

namespace arco::track {
namespace {

constexpr double kMinEdgeGapPx = 2;     // two edges closer than this: one line
constexpr double kMinEdgeShare = 0.15;  // of the segments' length, on each edge
// Direction and edges refitted in turn: the first direction mixes both edges, and each
// pass leaves about 1/60 of the last one's tilt (the unit test), so six leave well under
// 1e-6 px over 300 px.
constexpr int kPasses = 6;

}  // namespace

bool FitStickLine(std::vector<StickSegment>* segments,
                  Eigen::Vector2d* point,
                  Eigen::Vector2d* direction,
                  double* weight_out) {
  *weight_out = 0;
  std::vector<StickSegment>& segs = *segments;
  if (segs.empty()) return false;
  const size_t m = segs.size();
  std::vector<double> shift(m, 0.0);  // each segment's edge offset, removed in the fit
  Eigen::Vector2d mean = Eigen::Vector2d::Zero(), t = Eigen::Vector2d::UnitX();
  double centre = 0, weight = 0.5;
  for (int pass = 0; pass < kPasses; ++pass) {
    // Direction: TLS over the endpoints, each segment moved across by its shift.
    const Eigen::Vector2d n0(-t.y(), t.x());
    mean.setZero();
    double total = 0;
    for (size_t i = 0; i < m; ++i) {
      mean += segs[i].length * (segs[i].a + segs[i].b - 2 * shift[i] * n0);
      total += 2 * segs[i].length;
    }
    mean /= total;
    Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
    for (size_t i = 0; i < m; ++i)
      for (const Eigen::Vector2d& x : {segs[i].a, segs[i].b}) {
        const Eigen::Vector2d y = x - shift[i] * n0 - mean;
        scatter += segs[i].length * y * y.transpose();
      }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(scatter);
    Eigen::Vector2d t_new = eig.eigenvectors().col(1);
    if (pass > 0 && t_new.dot(t) < 0) t_new = -t_new;
    t = t_new;
    const Eigen::Vector2d n(-t.y(), t.x());
    // Offsets across the line, sorted; the best two-edge split.
    std::vector<std::pair<double, size_t>> offset(m);
    for (size_t i = 0; i < m; ++i) offset[i] = {n.dot(0.5 * (segs[i].a + segs[i].b) - mean), i};
    std::sort(offset.begin(), offset.end());
    double all_w = 0, all_wo = 0;
    for (const auto& [o, i] : offset) {
      all_w += segs[i].length;
      all_wo += segs[i].length * o;
    }
    double best = -1, w0 = 0, wo0 = 0;
    size_t split = 0;
    for (size_t k = 0; k + 1 < m; ++k) {
      w0 += segs[offset[k].second].length;
      wo0 += segs[offset[k].second].length * offset[k].first;
      const double w1 = all_w - w0;
      const double between = w0 * w1 * std::pow(wo0 / w0 - (all_wo - wo0) / w1, 2);
      if (between > best) {
        best = between;
        split = k + 1;
      }
    }
    // Weighted median offset of a range of the sorted offsets.
    const auto median = [&](size_t from, size_t to, double* w) {
      *w = 0;
      for (size_t k = from; k < to; ++k) *w += segs[offset[k].second].length;
      double acc = 0;
      for (size_t k = from; k < to; ++k) {
        acc += segs[offset[k].second].length;
        if (acc >= 0.5 * *w) return offset[k].first;
      }
      return offset[to - 1].first;
    };
    double wa = 0, wb = 0;
    const double oa = split > 0 ? median(0, split, &wa) : 0;
    const double ob = split > 0 ? median(split, m, &wb) : 0;
    if (split > 0 && ob - oa >= kMinEdgeGapPx && wa >= kMinEdgeShare * all_w &&
        wb >= kMinEdgeShare * all_w) {
      centre = 0.5 * (oa + ob);
      weight = 1;
      for (size_t k = 0; k < m; ++k) {
        const size_t i = offset[k].second;
        shift[i] = (k < split ? oa : ob) - centre;
      }
    } else {
      double w = 0;
      centre = median(0, m, &w);
      weight = 0.5;
      std::fill(shift.begin(), shift.end(), 0.0);
    }
    // The line through the centre; shift (relative to it) moves each segment onto it
    // in the next pass's TLS.
    mean += centre * n;
  }
  const Eigen::Vector2d n(-t.y(), t.x());
  for (size_t i = 0; i < m; ++i) {
    StickSegment& s = segs[i];
    const double da = n.dot(s.a - mean) - shift[i], db = n.dot(s.b - mean) - shift[i];
    s.residual_px = std::sqrt(0.5 * (da * da + db * db));
  }
  *point = mean;
  *direction = t;
  *weight_out = weight;
  return true;
}

}  // namespace arco::track
