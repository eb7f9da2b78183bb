// A skeleton of fixed bone lengths fitted to triangulated points (the arco method's body
// and right hand; docs/export.md, "BVH"). Triangulated joints move by several mm against
// each other from frame to frame (their bone lengths vary by ~5 mm median on the synthetic
// takes, the truth's by 0); a skeleton makes the points one consistent body, fills the
// joints a frame misses, and makes the BVH export reproduce them exactly.
//
// Per take: each bone's length is the median of its measured lengths; a joint with several
// children (hips, neck, nose, ankles, the hand wrist: the palm) gets one rigid shape, the
// component-wise median of its children's offsets after aligning each frame to a
// reference (Kabsch), each offset then scaled to its median length. Per frame: root
// position and one world rotation per joint, least squares of the weighted distances
// between forward kinematics and the measured points (Huber loss), warm-started from the
// previous frame and pulled weakly towards it, so a joint missing in a frame (or a
// rotation no point constrains, such as a bone's twist) keeps its previous pose.
//
// Parallel: the frames are cut into fixed chunks of chunk_frames, and the groups' chunks
// are fitted on num_threads threads. The chunks do not depend on the thread count, so
// neither do the results. Each chunk starts cold (from the tree fit, as the take's first
// frame does) warmup_frames before its first frame and keeps only its own frames: a cold
// start alone places a joint missing in that frame along its parent's bone (hundreds of
// mm off), while after the warm-up it has the pose of its last measurement, as in one
// pass over the take. Chunk boundaries then differ from one pass by the solver's
// tolerance, except where a joint is missing for the whole warm-up (skeleton_fit_test).
#pragma once

#include <string>
#include <vector>

#include "arco/body/skeleton.h"
#include "arco/util/npy.h"
#include "arco/util/status.h"

namespace arco::body {

struct SkeletonFitOptions {
  // The groups to fit (each a subtree of WholeBodySkeleton() hanging from its own root:
  // the hips for the body, the hand wrist for a hand).
  std::vector<JointGroup> groups = {JointGroup::kBody, JointGroup::kRightHand};
  // Huber loss scale (mm, on a point's weighted distance): beyond it a point counts
  // linearly, so one bad triangulation pulls the skeleton less.
  double robust_scale_mm = 20.0;
  // Weight (mm per radian) of each rotation's pull towards the previous frame.
  double rotation_prior_mm_per_rad = 0.01;
  int max_iterations = 100;
  // Frames per independently fitted chunk (see above); not a function of num_threads.
  int chunk_frames = 120;
  int warmup_frames = 30;  // fitted before a chunk's first frame and dropped
  int num_threads = 1;  // 0 = all cores; results do not depend on it

  Status Validate() const;
};

struct SkeletonFitResult {
  // The input points with the fitted groups' keypoints replaced by the skeleton's forward
  // kinematics on every frame where the group has a measured point (missing ones filled).
  NpyArray<double> points_mm;
  std::vector<JointGroup> fitted_groups;  // a group without a measurable bone stays raw
  // Per fitted group, the median |forward kinematics - measured point| (mm).
  std::vector<double> median_residual_mm;
};

// points_mm: (F, P, 3) millimetres, NaN = missing, named by `names` (arco keypoint names);
// weights: (F, P) per-point weights (a point with weight 0 is ignored) or empty for 1.
// Deterministic: the same bits for any num_threads.
StatusOr<SkeletonFitResult> FitSkeleton(const NpyArray<double>& points_mm,
                                        const std::vector<std::string>& names,
                                        const NpyArray<double>& weights,
                                        const SkeletonFitOptions& options);

}  // namespace arco::body
