// The bow as a thin rigid body of fixed length (`arco track --bow`, docs/track.md): its
// frog and tip triangulated from the labelled frame give the stick's axis and length, and
// the labelled frame gives, per view, the intensity profile under the stick (1 mm steps
// along the 3D axis, a little beyond frog and tip). Per frame, from a constant-velocity
// prediction of frog and tip (moved onto the right hand when `arco detect` found it far
// from the prediction, or after a lost frame):
//  1. per view, line segments (OpenCV's LSD, Grompone von Gioi et al., PAMI 2010) in a box
//     around the predicted stick, kept when they run parallel to it (angle gate) and near
//     it (distance gate); the stick's image line runs midway between its two edges
//     (bow_line.h: one robust line through them locked onto the edge with more segments);
//  2. per view, the slide along that line: the profile under it is matched with the
//     labelled frame's by normalised cross-correlation over +-slide_search_mm;
//  3. frog and tip are triangulated from the views that matched (rays weighted by the
//     match), then put the bow's fixed length apart: a first estimate;
//  4. (refine) the pose from all views at once (bow_pose_solver.h): frog and direction at
//     the fixed length, the views' lines and the stick's texture in every view, weak
//     priors on the predicted frog and tip and on the right hand; from the prediction
//     and from step 3's estimate, coarse to fine, the lower final cost wins.
// Step 3 alone left 10 mm median errors (docs/track.md): each view's slide is good to a
// few millimetres only and two-ray triangulation turns the views' disagreement into depth.
// Intersecting the views' line planes alone (no slide) was tried first: with cameras on
// an arc around the player, a bow lying along the arc's baselines gives planes that all
// but coincide, and the bow's depth came out 40-100 mm off.
// A frame in which fewer than two views match keeps the prediction, with a low score.
// OpenCV and Ceres are private: neither's types appear here.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <vector>

#include "arco/camera/camera.h"
#include "arco/media/image.h"
#include "arco/track/instrument_tracker.h"
#include "arco/util/json_io.h"
#include "arco/util/status.h"

namespace arco::track {

// A bow's frog and tip closer than this are not a bow (a violin bow is about 750 mm, a
// double bass's about 700 mm): bad labels, or a world not in mm.
constexpr double kMinBowLengthMm = 50;

struct BowTrackerOptions {
  double roi_margin_px = 40;      // the box around the predicted stick grown by this much
  double search_px = 15;          // segments farther than this from the predicted line: out
  double max_angle_deg = 6;       // segments turned more than this from it: out
  double min_segment_px = 8;      // shorter segments: out
  double huber_px = 2;            // segments within 3 x this of their edge: inliers
  double slide_search_mm = 40;    // +- along the axis around the predicted frog
  double profile_margin = 0.04;   // of the length, profiled beyond frog and tip
  double min_ncc = 0.3;           // a view whose profile matches less is not used
  bool refine = true;             // step 4 (off: step 3's estimate, as before)
  double coarse_blur_px = 2;      // step 4's first level: the frames' Gaussian sigma
  double fine_blur_px = 0.7;      // and its second
  double sample_step_mm = 2;      // texture samples along the stick
  double intensity_sigma = 8;     // grey levels: the texture term's scale
  double line_sigma_px = 1;       // the line term's scale
  double motion_sigma_mm = 20;    // the constant-velocity prior on frog and tip
  double hand_sigma_mm = 40;      // the right hand's prior on the frog
  double hand_reacquire_mm = 80;  // the hand this far from the predicted frog: move it
  int num_threads = 1;            // views in parallel; results do not depend on it
  Status Validate() const;
};

Json ToJson(const BowTrackerOptions& options);

class BowTracker {
 public:
  // frog and tip: the labelled frame's triangulated points. The world must be in mm
  // (every length option is mm): a caller with another unit scales the cameras'
  // translations and the points first (capture/track_steps.cc). Throws
  // std::invalid_argument on invalid options or a bow shorter than kMinBowLengthMm.
  BowTracker(std::vector<Camera> cameras,
             const Eigen::Vector3d& frog,
             const Eigen::Vector3d& tip,
             const BowTrackerOptions& options);
  ~BowTracker();
  BowTracker(BowTracker&&) noexcept;

  // The labelled frame (Gray8, the cameras' sizes): the stick's profile per view.
  // right_hand as in Next: seen there in two views, its offset from the frog (along the
  // stick and across it) is what Next's hand prior expects; without, the hand is taken
  // to be at the frog.
  TrackFrame Start(const std::vector<const media::Image*>& frames,
                   const std::vector<Eigen::Vector2d>* right_hand = nullptr);
  // The next frame in tracking order. labels: [view][frog, tip] of this frame (NaN =
  // none); both labelled in two views replace the estimate. Per view, the report's
  // `tracked` counts the segments found near the prediction, `inliers` those within
  // 3 x huber_px of their edge of the stick, `residual_px` their RMS distance to it,
  // `lost` a view without segments. TrackFrame::match_ncc is the views' mean profile match.
  // right_hand: [view] the right hand's pixel in this frame (e.g. the mean of the hand's
  // keypoints that `arco detect` scored; NaN = none); seen in two views, it is
  // triangulated and held at its labelled-frame offset from the frog
  // (BowTrackerOptions::hand_sigma_mm).
  TrackFrame Next(const std::vector<const media::Image*>& frames,
                  const std::vector<std::vector<Eigen::Vector2d>>* labels = nullptr,
                  const std::vector<Eigen::Vector2d>* right_hand = nullptr);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace arco::track
