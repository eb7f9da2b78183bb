// One camera: the refined hand held over the frames around, in the instrument's frame
// (issue 26 part 4).
//
// One view's hand fit jitters in depth from frame to frame (a few pixels of detector noise
// tilt a bone by degrees), while a player's left hand, in the frame of the instrument it
// holds, changes its posture over notes, not frames. After the refinement each frame's
// hand becomes, in the instrument's frame made from that frame's strings (origin the
// bridge's middle, x to the nut's, y across from the lowest string to the highest), the
// median of the wrist's positions and of each joint angle and the quaternion average of
// the wrist's rotations (geometry/rotation.h, AverageQuaternions) over the frames within
// `window_frames` each side that have a hand; a median keeps a shift's step where a mean
// would smear it. A pressed frame's hand is then moved so that its playing fingertip is
// where the refinement put it (the decisions and contacts do not change). On arco's own
// refined output of the real take (30 one-camera captures), the keypoints' median over
// +-6 frames in the instrument's frame took the hand within 15 mm 0.436 -> 0.494 (a check
// in Python before this was built).
#pragma once

#include <optional>
#include <vector>

#include "arco/refine/contact_annotation.h"
#include "arco/refine/decode_context.h"

namespace arco::refine {

// Frames without strings or a hand are left as they are and take no part. Returns the
// number of frames changed. Deterministic (each frame reads the input hands only).
int SmoothHandsInInstrumentFrame(const DecodeContext& context,
                                 const std::vector<FrameContact>& contacts,
                                 int window_frames,
                                 int num_threads,
                                 std::vector<std::optional<hand::HandPose>>* hands);

}  // namespace arco::refine
