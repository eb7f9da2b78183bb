// The audio-guided correction of the playing finger (Jin et al. 2024, Eq. 3), on top of the
// hand layer's bounded fingertip IK (hand/ik.h: joint limits as hard bounds, so no refined
// pose can violate a limit).
//
// Paper mode: PIP and DIP flexion of the bound finger only (kPipDip), started from and
// weakly pulled toward the fitted pose; whatever distance remains is reported, no frame is
// rejected (the paper has no lift test).
//
// arco mode, frames independent (parallel) in each pass:
//  1. bounded IK over MCP flexion and abduction, PIP and DIP (ArcoIkOptions::joints) with a
//     prior toward the fitted (vision) angles;
//  2. the pass-1 angles of the playing finger are smoothed with a Gaussian over time within
//     each run of frames sharing note, string and finger; a second IK per frame adds a prior
//     toward that smoothed solution (temporal smoothness without a sequential dependency);
//  3. lift test: a solution whose tip stays farther than max_residual_mm from the contact
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
