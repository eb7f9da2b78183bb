// The audio-guided correction of the playing finger (Jin et al. 2024, Eq. 3), on top of the
// hand layer's bounded fingertip IK (hand/ik.h: joint limits as hard bounds, so no refined
// pose can violate a limit).
//
// Paper mode: PIP and DIP flexion of the bound finger only (kPipDip), started from and
// weakly pulled toward the fitted pose; whatever distance remains is reported, no frame is
// rejected (the paper has no lift test).
//
// arco mode:
//  1. bounded IK over MCP flexion and abduction, PIP and DIP (ArcoIkOptions::joints) with a
//     prior toward the fitted (vision) angles and, for temporal smoothness, toward the
//     previous frame's solution. Frames are chained in time order only within a run (the
//     consecutive frames of one note with the same string and finger); runs are
//     independent and solved in parallel, so results do not depend on the thread count;
//  2. lift test: a solution whose tip stays farther than max_residual_mm from the contact
//     is rejected (the finger cannot reach it), the frame flagged kOutOfReach and its hand
//     left as fitted. (The decoder already rejected contacts beyond the lift distance.)
// Other fingers, the thumb and the wrist are never changed.
#pragma once

#include <optional>
#include <vector>

#include "arco/refine/decode_context.h"

namespace arco::refine {

struct IkStats {
  int solves = 0;
  int iterations = 0;
  int not_converged = 0;
};

// `contacts` from a decoder; on return the refined hands (the vision hand where nothing
// changed) and the contacts' tip_distance_refined_mm (and arco's rejections) are set.
std::vector<std::optional<hand::HandPose>> SolvePaperIk(const DecodeContext& context,
                                                        const PaperOptions& options,
                                                        std::vector<FrameContact>* contacts,
                                                        IkStats* stats,
                                                        int num_threads);

std::vector<std::optional<hand::HandPose>> SolveArcoIk(const DecodeContext& context,
                                                       const ArcoIkOptions& options,
                                                       std::vector<FrameContact>* contacts,
                                                       IkStats* stats,
                                                       int num_threads);

}  // namespace arco::refine
