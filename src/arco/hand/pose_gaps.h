// Short gaps in a fitted hand's track (frames whose fit was flagged) filled from the fitted
// frames on either side.
//
// A frame whose fit fails (too few trusted views, the gate) would otherwise carry the
// triangulated keypoints, which no hand model stands behind: on the real take seen by four
// cameras from behind (error model `behind`, seed 1) one such frame had a little finger
// bent 90 degrees backwards. A hand moves smoothly over a few frames (30 fps: 33 ms each),
// so between two fitted poses at most `max_gap_frames` apart the pose is interpolated:
// every joint angle linearly (the limits are a box, so the angles stay within them), the
// wrist's rotation by slerp, its position linearly. Longer gaps, and gaps at the start or
// end of the take, stay empty: nothing says what the hand did there.
#pragma once

#include <optional>
#include <vector>

#include "arco/hand/hand_model.h"
#include "arco/util/status.h"

namespace arco::hand {

struct PoseGapOptions {
  int max_gap_frames = 5;  // [0, 1000]: the longest gap filled (0: none)
  Status Validate() const;
};

// Fills the gaps of `hands` (above); returns how many frames it filled. Errors: invalid
// options. Deterministic.
StatusOr<int> FillHandPoseGaps(const PoseGapOptions& options,
                               std::vector<std::optional<HandPose>>* hands);

}  // namespace arco::hand
