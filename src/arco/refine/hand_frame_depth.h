// One camera: the pressed frames' vision hands placed along their rays by the hand frame
// (issue 26 part 4; hand/ray_depth.h does the moving).
//
// Once the sound has decided a frame's string, finger and contact, it also says where
// the other fingertips are along that string: a player's hand stands in a frame, finger j
// of the instrument's closed hand frame FingerOffsetSemitones(j) - FingerOffsetSemitones(k)
// semitones from the pressing finger k (cello: one semitone per finger), so its tip is at
// the vibrating length x_k 2^(-(o_j - o_k) / 12) from the bridge, lifted or not. One view
// cannot tell how far along its ray a fingertip lies; with the camera 35 degrees off the
// strings (the real take's camera 21334207) a place along the string is most of that.
// On SPD's cellist (cello01, 262 pressed frames) the other fingertips lie within -2..+15 mm
// of those places (quartiles; medians +1, +1, +5, +6 mm for fingers 1-4), so the places
// are targets with sigma one_view_frame_sigma_mm (10): the index's, a semitone per
// finger, not the first position's spacing in mm (medians -1..+20 mm).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "arco/hand/ray_depth.h"
#include "arco/refine/contact_annotation.h"
#include "arco/refine/decode_context.h"

namespace arco::refine {

// For every pressed frame (finger 1-4, a finite contact on a string of that frame, a
// vision hand): the hand moved along its rays from `camera_centre_mm` so that the
// pressing fingertip is as far from the camera as the contact and the other fingertips
// at their places in the hand frame (header comment). Frames where that fails keep
// their hand. Returns the number of frames moved; parallel over frames (each its own).
int PlaceHandsInTheirFrame(const DecodeContext& context,
                           const std::vector<FrameContact>& contacts,
                           const Eigen::Vector3d& camera_centre_mm,
                           const HandFrameDepthOptions& options,
                           int num_threads,
                           std::vector<std::optional<hand::HandPose>>* hands);

}  // namespace arco::refine
