// The depth of a hand fitted in ONE view (issue 26 part 4, track/monocular_lift.h).
//
// One view fixes a fitted hand's depth only through its size in the image, which a few
// pixels of detector noise move by centimetres. Where the hand's fingertips are known to
// lie (at the depth of the strings they play, from the instrument's pose), the fitted hand
// is moved along its wrist's ray so that its four fingertips' median depth is that depth.
// The shift is a median over the frames around (the hand's depth changes slowly; the
// fingertips do not all touch the strings in every frame). The wrist's image stays; the
// rest of the hand's image scales by about shift / depth (1-5 % here).
#pragma once

#include <optional>
#include <vector>

#include "arco/camera/camera.h"
#include "arco/hand/hand_model.h"
#include "arco/hand/kinematics.h"
#include "arco/util/status.h"

namespace arco::hand {

struct OneViewDepthOptions {
  int window_frames = 15;  // [0, 300]: the shift is the median over this many frames each side
  Status Validate() const;
};

struct OneViewDepthSummary {
  int frames_moved = 0;
  double median_shift_mm = 0;  // signed, along the rays (+: away from the camera); NaN: none
};

// `tip_depth_mm[f]`: the camera depth (z in its frame, mm) the fingertips should have in
// frame f; NaN when unknown. `hands` (world mm) are moved in place; frames without a hand
// stay empty. Errors: invalid options, sizes that differ.
StatusOr<OneViewDepthSummary> AlignHandDepth(const HandModel& model,
                                             const Camera& camera_mm,
                                             const std::vector<double>& tip_depth_mm,
                                             const OneViewDepthOptions& options,
                                             std::vector<std::optional<HandPose>>* hands);

}  // namespace arco::hand
