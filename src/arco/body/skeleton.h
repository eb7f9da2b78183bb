// The one whole-body skeleton of arco: the tree the BVH export writes (export/bvh.cc) and
// the one `arco run` fits to the arco method's body and right hand (skeleton_fit.h), so
// that the exporter's re-fit of those points is exact (docs/export.md, "BVH").
//
//   hips (root: mid left_hip/right_hip)
//     left_hip > left_knee > left_ankle > left_big_toe, left_small_toe, left_heel (right alike)
//     neck (mid shoulders) > nose > left_eye > left_ear (right alike)
//       left_shoulder > left_elbow > left_wrist > left_hand_wrist > left_hand_thumb_cmc >
//         .._mcp > .._ip > .._tip, and index/middle/ring/little mcp > pip > dip > tip
//       (right alike)
//
// Joints are named by arco's keypoint names (registry/keypoint_layout.h); hips and neck are
// midpoints of two keypoints. The hand wrists are "positioned": each hand hangs from its
// own measured wrist, not from the forearm (two estimates of one joint).
#pragma once

#include <string>
#include <vector>

namespace arco::body {

enum class JointGroup { kBody = 0, kLeftHand = 1, kRightHand = 2 };

struct SkeletonJoint {
  std::string name;
  int parent = -1;  // index in the skeleton; -1 for the root
  std::vector<int> children;
  // The keypoint the joint sits on; empty for a midpoint joint (hips, neck).
  std::string keypoint;
  std::string mid_a, mid_b;  // a midpoint joint's two keypoints
  JointGroup group = JointGroup::kBody;
  bool positioned = false;  // placed at its own point (the hand wrists)
};

// The skeleton in depth-first order (every parent before its children).
const std::vector<SkeletonJoint>& WholeBodySkeleton();

}  // namespace arco::body
