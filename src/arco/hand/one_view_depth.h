// The depth of a hand fitted in ONE view (issue 26 part 4, track/monocular_lift.h).
//
// One view fixes a fitted hand's depth only through its size in the image, which a few
// pixels of detector noise move by centimetres. Where something else says how far from
// the camera a fingertip is (the strings its fingertips play, from the instrument's pose;
// the contact point of the note the sound says it presses), the fitted hand is moved
// along its wrist's ray from the camera by that difference: every keypoint moves by the
// same vector, so a fingertip's distance from the camera changes by the shift (to the
// cosine of the small angle between its ray and the wrist's), and the wrist's image stays
// where it was. Each frame's wrist goes to the median over the frames around of the
// wanted wrist distances (its distance plus its shift): a hand's depth changes slowly,
// single frames are wrong, and the fit's own depth jitters from frame to frame.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "arco/hand/hand_model.h"
#include "arco/hand/kinematics.h"
#include "arco/util/status.h"

namespace arco::hand {

struct OneViewDepthOptions {
  int window_frames = 15;  // [0, 300]: the wanted distance's median over this many frames each side
  Status Validate() const;
};

struct OneViewDepthSummary {
  int frames_moved = 0;
  double median_shift_mm = 0;  // signed, along the rays (+: away from the camera); NaN: none
};

// Moves each frame's hand (world mm) along its wrist's ray from `camera_centre_mm` to the
// median over the frames around of the wanted wrist distances (each frame's distance plus
// its `shift_mm`; NaN: unknown); frames without a hand stay empty, frames with no known
// shift around stay where they are. Errors: invalid options, sizes that differ.
StatusOr<OneViewDepthSummary> MoveHandsAlongRays(const Eigen::Vector3d& camera_centre_mm,
                                                 const std::vector<double>& shift_mm,
                                                 const OneViewDepthOptions& options,
                                                 std::vector<std::optional<HandPose>>* hands);

// The shifts that put each frame's four fingertips' median distance from the camera at
// `tip_distance_mm[f]` (NaN: unknown), then MoveHandsAlongRays.
StatusOr<OneViewDepthSummary> AlignHandDepth(const HandModel& model,
                                             const Eigen::Vector3d& camera_centre_mm,
                                             const std::vector<double>& tip_distance_mm,
                                             const OneViewDepthOptions& options,
                                             std::vector<std::optional<HandPose>>* hands);

}  // namespace arco::hand
