// Hands checked against each other across calibrated views (issue 28, part 2): the hand
// landmarker sees one view at a time, so a view can put a hand's fingers where the other
// views do not, or give the left hand's points to the right. After a frame is detected in
// every view, each hand is triangulated robustly from all views (the consensus,
// mocap/triangulate_point.h), and every view's hand is compared with the consensus
// reprojected into it:
//   1. swap: a view whose left and right hands match the consensus much better the other
//      way round gets them swapped (a classic detector error);
//   2. a view whose hand disagrees (median reprojection error of its points above the
//      gate, which grows with the hand's size in that view) is listed with a crop centred
//      on the reprojected consensus hand (MediaPipe's landmarks-to-ROI rule), for the
//      caller to re-run the hand landmarker there (`arco detect`: capture/detect_stage.cc);
//      a re-run that agrees replaces the hand, otherwise its points are down-weighted;
//   3. single points of an agreeing view far off the consensus are down-weighted.
// Down-weighting sets a point's score to `low_score` (below triangulation's and the hand
// fit's min_score, 0.3: both then ignore it) and keeps its pixel.
//
// Pixels follow the OpenCV convention (camera/camera.h); a frame's keypoints are rows of
// COCO-WholeBody points (x_px, y_px, score) per view, as in keypoints2d.npy. Everything
// here is deterministic and free of threads; frames are independent of each other.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "arco/camera/camera.h"
#include "arco/detect/roi.h"
#include "arco/mocap/triangulate_point.h"
#include "arco/util/json_io.h"
#include "arco/util/number_range.h"
#include "arco/util/status.h"

namespace arco::capture {

inline constexpr int kHandPoints = 21;  // hand_21, the wrist first

// Declared ranges of HandConsistencyOptions' numbers (util/number_range.h).
inline constexpr NumberRange kHandGatePxRange = Closed(0, 1000);
inline constexpr NumberRange kHandGateFractionRange = Closed(0, 2);
inline constexpr NumberRange kHandScoreRange = Closed(0, 1);
inline constexpr NumberRange kHandSwapRatioRange = Closed(0, 1);
inline constexpr NumberRange kHandMinViewsRange = Closed(2, 1000);

struct HandConsistencyOptions {
  bool enabled = true;
  // Hand points below this score take no part (triangulation's and the hand fit's 0.3).
  double min_score = 0.3;
  // The consensus: each point triangulated robustly with this RANSAC gate (px), and kept
  // when at least min_views views agree on it (with two, neither can be judged).
  double max_reprojection_px = 15;
  int min_views = 3;
  // A view's hand disagrees when the median reprojection error of its points exceeds
  // max(max_error_px, max_error_hand_fraction x the hand's size in that view); the size is
  // the diagonal of the reprojected consensus hand's bounding box.
  double max_error_px = 4;
  double max_error_hand_fraction = 0.08;
  // A point of an agreeing hand is down-weighted when its own error exceeds
  // max(max_error_px, max_point_error_hand_fraction x the hand's size).
  double max_point_error_hand_fraction = 0.25;
  // Left and right are swapped in a view when the swapped error is below this fraction of
  // the unswapped one (and within the gate).
  double swap_max_error_ratio = 0.5;
  // Re-run the hand landmarker in disagreeing views on a crop around the consensus
  // before down-weighting them (the frame is decoded again). Off by default: on the plane
  // test no re-run agreed (the landmarker reads the view the same way from a better
  // crop) and they cost about 20 ms per view-frame (docs/performance.md, issue 28).
  bool rerun = false;
  // The score a down-weighted point gets (below min_score).
  double low_score = 0.05;
  Status Validate() const;
};

Json ToJson(const HandConsistencyOptions& options);

// One hand triangulated from every view of a frame.
struct HandConsensus {
  std::array<Eigen::Vector3d, kHandPoints> point_in_world;
  std::array<bool, kHandPoints> valid{};  // triangulated with >= min_views agreeing views
  int num_valid = 0;
};

// How one view's hand compares with the consensus.
struct HandViewCheck {
  bool judged = false;     // enough points of both to compare (a third of the hand)
  double error_px = NAN;   // median reprojection error of its points
  double size_px = NAN;    // the reprojected consensus hand's bounding-box diagonal
  double gate_px = NAN;    // max(max_error_px, max_error_hand_fraction * size_px)
  bool disagrees = false;  // judged and error_px > gate_px
  // Where to re-run the hand landmarker (disagreeing views only).
  std::optional<detect::Roi> recrop;
};

// What CheckFrameHands found and did in one frame.
struct FrameHandCheck {
  std::array<HandConsensus, 2> consensus;           // left, right
  std::vector<std::array<HandViewCheck, 2>> views;  // by view: left, right
  std::vector<uint8_t> swapped;                     // by view
  int64_t points_down_weighted = 0;                 // single points (step 3)
};

// Counts over a clip (detect.json, `arco detect`'s output).
struct HandConsistencySummary {
  bool ran = false;
  std::string skipped;               // why it did not run (empty when it ran)
  int64_t hands_judged = 0;          // (view, frame, hand) compared with a consensus
  int64_t swapped = 0;               // (view, frame) whose hands were swapped
  int64_t disagreeing = 0;           // hands above the gate
  int64_t recropped = 0;             // of those, re-run on the consensus crop
  int64_t fixed = 0;                 // of those, re-runs that agree and replaced the hand
  int64_t hands_down_weighted = 0;   // disagreeing hands down-weighted whole
  int64_t points_down_weighted = 0;  // all points given low_score (whole hands included)
  double wall_s = 0;  // the whole check: consensus, decoding, re-runs (not deterministic)
  void Merge(const HandConsistencySummary& other);
};

Json ToJson(const HandConsistencySummary& summary);

// A frame's keypoints of every view: `views` rows of at least wholebody::kNumPoints
// points (x, y, score), row v starting at data + v * view_stride floats; cameras[v] is
// view v's calibration camera. Swaps hands (step 1) and down-weights single points
// (step 3) in place; lists disagreeing views with their crops (step 2) but leaves them
// as they are. `triangulator` must be built on a rig whose cameras are the views', in
// order. Throws std::invalid_argument on invalid options, a rig of another size or rows
// shorter than WholeBody's (caller bugs).
FrameHandCheck CheckFrameHands(const HandConsistencyOptions& options,
                               const Triangulator& triangulator,
                               float* data,
                               int views,
                               int64_t view_stride);

// The triangulation options of the consensus.
TriangulationOptions ConsensusTriangulationOptions(const HandConsistencyOptions& options);

// The median reprojection error (px) of a view's 21 hand points (x, y, score) against the
// consensus in `camera`; NaN when fewer than a third of them can be compared.
double HandErrorPx(const HandConsistencyOptions& options,
                   const HandConsensus& consensus,
                   const Camera& camera,
                   const float* hand);

// MediaPipe's crop around a hand (HandLandmarksToRectCalculator): turned so the wrist ->
// middle of the finger bases points up, the bounding box of the points in that frame,
// its longer side x 2, shifted by 0.1 side towards the fingers. Empty without the wrist
// or the finger bases.
std::optional<detect::Roi> HandRoiFromPoints(const std::array<Eigen::Vector2d, kHandPoints>& px,
                                             const std::array<bool, kHandPoints>& valid);

// Step 3 on one view's hand: points whose reprojection error against the consensus
// exceeds max(max_error_px, max_point_error_hand_fraction x the hand's size) get
// low_score; returns how many it lowered.
int64_t DownWeightPointsOffConsensus(const HandConsistencyOptions& options,
                                     const HandConsensus& consensus,
                                     const Camera& camera,
                                     float* hand);

// Sets the score of a hand's 21 points (x, y, score) to min(score, low_score); returns how
// many it lowered.
int64_t DownWeightHand(const HandConsistencyOptions& options, float* hand);

}  // namespace arco::capture
