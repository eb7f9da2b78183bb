#include "arco/capture/hand_consistency.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "arco/registry/keypoint_layout.h"
#include "arco/util/stats.h"

namespace arco::capture {
namespace {

// A hand is compared when at least this many of its points can be (a third of them).
constexpr int kMinComparedPoints = 7;

bool Usable(const HandConsistencyOptions& o, const float* p) {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]) && p[2] >= o.min_score;
}

float* HandOf(float* data, int64_t view_stride, int view, int hand) {
  return data + view * view_stride +
         3 * (hand == 0 ? wholebody::kLeftHandFirst : wholebody::kRightHandFirst);
}

// The consensus reprojected into `camera`, and its bounding-box diagonal.
struct Reprojected {
  std::array<Eigen::Vector2d, kHandPoints> px;
  std::array<bool, kHandPoints> valid{};
  double size_px = NAN;
};

Reprojected Reproject(const HandConsensus& c, const Camera& camera) {
  Reprojected r;
  Eigen::Vector2d lo(INFINITY, INFINITY), hi(-INFINITY, -INFINITY);
  int n = 0;
  for (int i = 0; i < kHandPoints; ++i) {
    if (!c.valid[i]) continue;
    const std::optional<Eigen::Vector2d> p = camera.Project(c.point_in_world[i]);
    if (!p || !p->allFinite()) continue;
    r.px[i] = *p;
    r.valid[i] = true;
    lo = lo.cwiseMin(*p);
    hi = hi.cwiseMax(*p);
    ++n;
  }
  if (n >= 2) r.size_px = (hi - lo).norm();
  return r;
}

// Per-point errors (NaN where not comparable) and their median.
double Errors(const HandConsistencyOptions& o,
              const Reprojected& r,
              const float* hand,
              std::array<double, kHandPoints>* errors) {
  std::vector<double> e;
  for (int i = 0; i < kHandPoints; ++i) {
    (*errors)[i] = NAN;
    const float* p = hand + 3 * i;
    if (!r.valid[i] || !Usable(o, p)) continue;
    (*errors)[i] = (Eigen::Vector2d(p[0], p[1]) - r.px[i]).norm();
    e.push_back((*errors)[i]);
  }
  if (static_cast<int>(e.size()) < kMinComparedPoints) return NAN;
  return Median(e);
}

HandConsensus TriangulateHand(const HandConsistencyOptions& o,
                              const Triangulator& triangulator,
                              float* data,
                              int views,
                              int64_t view_stride,
                              int hand,
                              TriangulationScratch* scratch) {
  HandConsensus c;
  std::vector<PointObservation> obs;
  for (int i = 0; i < kHandPoints; ++i) {
    c.point_in_world[i].setConstant(NAN);
    obs.clear();
    for (int v = 0; v < views; ++v) {
      const float* p = HandOf(data, view_stride, v, hand) + 3 * i;
      if (!Usable(o, p)) continue;
      obs.push_back({v, Eigen::Vector2d(p[0], p[1]), p[2]});
    }
    if (static_cast<int>(obs.size()) < o.min_views) continue;
    const std::optional<TriangulatedPoint> t = triangulator.Triangulate(obs, scratch);
    if (!t || static_cast<int>(t->inlier_cameras.size()) < o.min_views) continue;
    c.point_in_world[i] = t->point_in_world;
    c.valid[i] = true;
    ++c.num_valid;
  }
  return c;
}

double Gate(const HandConsistencyOptions& o, double size_px, double fraction) {
  return std::max(o.max_error_px, fraction * size_px);
}

}  // namespace

Status HandConsistencyOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(CheckInRange("min_score", min_score, kHandScoreRange));
  ARCO_RETURN_IF_ERROR(CheckInRange("max_reprojection_px", max_reprojection_px, kHandGatePxRange));
  if (!(max_reprojection_px > 0)) return Status::Error("max_reprojection_px must be > 0");
  ARCO_RETURN_IF_ERROR(CheckInRange("min_views", min_views, kHandMinViewsRange));
  ARCO_RETURN_IF_ERROR(CheckInRange("max_error_px", max_error_px, kHandGatePxRange));
  ARCO_RETURN_IF_ERROR(
      CheckInRange("max_error_hand_fraction", max_error_hand_fraction, kHandGateFractionRange));
  ARCO_RETURN_IF_ERROR(CheckInRange(
      "max_point_error_hand_fraction", max_point_error_hand_fraction, kHandGateFractionRange));
  ARCO_RETURN_IF_ERROR(
      CheckInRange("swap_max_error_ratio", swap_max_error_ratio, kHandSwapRatioRange));
  ARCO_RETURN_IF_ERROR(CheckInRange("low_score", low_score, kHandScoreRange));
  if (low_score >= min_score) {
    return Status::Error("low_score " + std::to_string(low_score) + " must be below min_score " +
                         std::to_string(min_score) + " (a down-weighted point must be ignored)");
  }
  return Status::Ok();
}

Json ToJson(const HandConsistencyOptions& o) {
  return Json{{"enabled", o.enabled},
              {"min_score", o.min_score},
              {"max_reprojection_px", o.max_reprojection_px},
              {"min_views", o.min_views},
              {"max_error_px", o.max_error_px},
              {"max_error_hand_fraction", o.max_error_hand_fraction},
              {"max_point_error_hand_fraction", o.max_point_error_hand_fraction},
              {"swap_max_error_ratio", o.swap_max_error_ratio},
              {"rerun", o.rerun},
              {"low_score", o.low_score}};
}

void HandConsistencySummary::Merge(const HandConsistencySummary& other) {
  hands_judged += other.hands_judged;
  swapped += other.swapped;
  disagreeing += other.disagreeing;
  recropped += other.recropped;
  fixed += other.fixed;
  hands_down_weighted += other.hands_down_weighted;
  points_down_weighted += other.points_down_weighted;
  wall_s += other.wall_s;
}

Json ToJson(const HandConsistencySummary& s) {
  Json j{{"ran", s.ran},
         {"hands_judged", s.hands_judged},
         {"swapped", s.swapped},
         {"disagreeing", s.disagreeing},
         {"recropped", s.recropped},
         {"fixed", s.fixed},
         {"hands_down_weighted", s.hands_down_weighted},
         {"points_down_weighted", s.points_down_weighted},
         {"wall_s", s.wall_s}};
  if (!s.skipped.empty()) j["skipped"] = s.skipped;
  return j;
}

TriangulationOptions ConsensusTriangulationOptions(const HandConsistencyOptions& o) {
  TriangulationOptions t;
  t.min_score = o.min_score;
  t.max_reprojection_px = o.max_reprojection_px;
  return t;
}

double HandErrorPx(const HandConsistencyOptions& options,
                   const HandConsensus& consensus,
                   const Camera& camera,
                   const float* hand) {
  std::array<double, kHandPoints> errors;
  return Errors(options, Reproject(consensus, camera), hand, &errors);
}

std::optional<detect::Roi> HandRoiFromPoints(const std::array<Eigen::Vector2d, kHandPoints>& px,
                                             const std::array<bool, kHandPoints>& valid) {
  std::array<detect::Point2, kHandPoints> points;
  for (int i = 0; i < kHandPoints; ++i) points[i] = {px[i].x(), px[i].y()};
  return detect::HandRoiFromLandmarks(points.data(), valid.data());
}

int64_t DownWeightPointsOffConsensus(const HandConsistencyOptions& o,
                                     const HandConsensus& consensus,
                                     const Camera& camera,
                                     float* hand) {
  const Reprojected r = Reproject(consensus, camera);
  std::array<double, kHandPoints> errors;
  if (std::isnan(Errors(o, r, hand, &errors)) || !std::isfinite(r.size_px)) return 0;
  const double point_gate = Gate(o, r.size_px, o.max_point_error_hand_fraction);
  int64_t n = 0;
  for (int i = 0; i < kHandPoints; ++i) {
    float& score = hand[3 * i + 2];
    if (errors[i] > point_gate && score > static_cast<float>(o.low_score)) {
      score = static_cast<float>(o.low_score);
      ++n;
    }
  }
  return n;
}

int64_t DownWeightHand(const HandConsistencyOptions& options, float* hand) {
  int64_t n = 0;
  for (int i = 0; i < kHandPoints; ++i) {
    float& score = hand[3 * i + 2];
    if (std::isfinite(score) && score > static_cast<float>(options.low_score)) {
      score = static_cast<float>(options.low_score);
      ++n;
    }
  }
  return n;
}

FrameHandCheck CheckFrameHands(const HandConsistencyOptions& o,
                               const Triangulator& triangulator,
                               float* data,
                               int views,
                               int64_t view_stride) {
  if (const Status valid = o.Validate(); !valid.ok()) {
    throw std::invalid_argument("CheckFrameHands: " + valid.message());
  }
  const std::vector<Camera>& cameras = triangulator.rig().cameras;
  if (static_cast<int>(cameras.size()) != views) {
    throw std::invalid_argument("CheckFrameHands: " + std::to_string(views) + " views but " +
                                std::to_string(cameras.size()) + " cameras in the rig");
  }
  if (view_stride < 3 * wholebody::kNumPoints) {
    throw std::invalid_argument("CheckFrameHands: a view's row is shorter than WholeBody's");
  }
  FrameHandCheck out;
  out.views.resize(views);
  out.swapped.assign(views, 0);
  TriangulationScratch scratch;
  const auto triangulate_both = [&] {
    for (int h = 0; h < 2; ++h) {
      out.consensus[h] = TriangulateHand(o, triangulator, data, views, view_stride, h, &scratch);
    }
  };
  triangulate_both();

  // 1. Swapped hands: compare each view's hands with both consensus hands.
  std::array<double, kHandPoints> errors;
  std::vector<std::array<Reprojected, 2>> reprojected(views);
  for (int v = 0; v < views; ++v) {
    for (int h = 0; h < 2; ++h) reprojected[v][h] = Reproject(out.consensus[h], cameras[v]);
  }
  bool any_swap = false;
  for (int v = 0; v < views; ++v) {
    double kept = 0, swapped = 0;
    int terms = 0;
    bool within_gate = true;
    for (int h = 0; h < 2; ++h) {
      const float* hand = HandOf(data, view_stride, v, h);
      const double same = Errors(o, reprojected[v][h], hand, &errors);
      const double other = Errors(o, reprojected[v][1 - h], hand, &errors);
      if (std::isnan(same) && std::isnan(other)) continue;  // no such hand (or consensus)
      if (std::isnan(same) || std::isnan(other)) {
        terms = 0;  // one side cannot be compared: no verdict for this view
        break;
      }
      kept += same;
      swapped += other;
      ++terms;
      within_gate =
          within_gate && other <= Gate(o, reprojected[v][1 - h].size_px, o.max_error_hand_fraction);
    }
    if (terms > 0 && within_gate && swapped < o.swap_max_error_ratio * kept) {
      float* left = HandOf(data, view_stride, v, 0);
      float* right = HandOf(data, view_stride, v, 1);
      std::swap_ranges(left, left + 3 * kHandPoints, right);
      out.swapped[v] = 1;
      any_swap = true;
    }
  }
  if (any_swap) {
    triangulate_both();
    for (int v = 0; v < views; ++v) {
      for (int h = 0; h < 2; ++h) reprojected[v][h] = Reproject(out.consensus[h], cameras[v]);
    }
  }

  // 2. and 3. Each view's hand against its consensus.
  for (int v = 0; v < views; ++v) {
    for (int h = 0; h < 2; ++h) {
      HandViewCheck& c = out.views[v][h];
      float* hand = HandOf(data, view_stride, v, h);
      const Reprojected& r = reprojected[v][h];
      c.error_px = Errors(o, r, hand, &errors);
      if (std::isnan(c.error_px) || !std::isfinite(r.size_px)) continue;
      c.judged = true;
      c.size_px = r.size_px;
      c.gate_px = Gate(o, r.size_px, o.max_error_hand_fraction);
      c.disagrees = c.error_px > c.gate_px;
      if (c.disagrees) {
        c.recrop = HandRoiFromPoints(r.px, r.valid);
        continue;
      }
      out.points_down_weighted +=
          DownWeightPointsOffConsensus(o, out.consensus[h], cameras[v], hand);
    }
  }
  return out;
}

}  // namespace arco::capture
