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
//
// The same note comes back: a player's hand returns to the same posture each time it
// stops the same note with the same finger on the same string, while one view's depth
// errors differ between the occurrences (other moments, other detector errors). So a
// pressed frame's held keypoints are blended, with weight `same_note_weight`, with their
// median over every pressed frame of the take that plays the same (string, finger,
// equal-tempered pitch) -- where at least kMinSameNoteFrames frames do. On arco's refined
// output of the real take (10 one-camera captures) a check in Python first: weight 0.5 took
// the hand within 15 mm in the instrument's frame 0.489 -> 0.546 (1: 0.486). Built in, over
// 30 captures (5 error models x 6 seeds): 0.466 -> 0.495 with weight 0.4 (0.3: 0.495, 0.5:
// 0.491, 0.6: 0.482); docs/accuracy.md, "One camera: the hand on the same note".
#pragma once

#include <optional>
#include <vector>

#include "arco/refine/contact_annotation.h"
#include "arco/refine/decode_context.h"

namespace arco::refine {

inline constexpr int kMinSameNoteFrames = 3;

// Frames without strings or a hand are left as they are and take no part. Returns the
// number of frames changed. Deterministic (each frame reads the input hands only).
// `same_note_weight` in [0, 1] (0: the window's median alone).
int SmoothHandsInInstrumentFrame(const DecodeContext& context,
                                 const std::vector<FrameContact>& contacts,
                                 int window_frames,
                                 double same_note_weight,
                                 int num_threads,
                                 std::vector<std::optional<hand::HandPose>>* hands);

}  // namespace arco::refine
