// The audio-guided correction of the playing finger (Jin et al. 2024, Eq. 3), on top of the
// hand layer's bounded fingertip IK (hand/ik.h: joint limits as hard bounds, so no refined
// pose can violate a limit).
//
// Paper mode: PIP and DIP flexion of the bound finger only (kPipDip), started from and
// weakly pulled toward the fitted pose; whatever distance remains is reported, no frame is
// rejected (the paper has no lift test).
//
// arco mode:
//  1. bounded IK over MCP flexion, PIP and DIP (ArcoIkOptions::joints), one regularised
//     solve with a prior toward the fitted (vision) angles and, for temporal smoothness,
//     toward the previous frame's solution: the least change that puts the tip on the
//     contact (a sub-millimetre residual remains; exact_reach removes it at a cost in
//     joint accuracy).
//     Frames are chained in time order only within a run (the consecutive frames of one
//     note with the same string and finger); runs are independent and solved in parallel,
//     so results do not depend on the thread count;
//  2. a solution whose tip stays farther than max_residual_mm from the contact moves the
//     whole hand rigidly by the remaining offset when that is at most max_hand_shift_mm
//     (kHandShifted: the fitted wrist is off, e.g. a fit lagging a shift); beyond that the
//     lift test rejects the contact (kOutOfReach: the finger cannot reach it) and the hand
//     stays as fitted. (The decoder already rejected contacts beyond the lift distance.)
//  3. the fitted hand lags fast shifts: a rejected frame whose nearest accepted frames of
//     the same note, string and finger (within neighbour_shift_frames) moved the whole
//     hand starts again from the fitted hand moved by their mean shift (kHandShifted when
//     the rest is within max_hand_shift_mm); a wrong decode has no accepted neighbours;
//  4. the sound lags the hand at note changes: a rejected frame just before the next note
//     gets that note's contact (kBeforeOnset) when its finger can reach it.
// Other fingers and the thumb keep their fitted angles; the wrist moves only in steps 2-3.
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

// lead_frames: a contact rejected this close before the next note's first pressed frame is
// tried again with that note's contact (the sound lags the hand at note changes).
std::vector<std::optional<hand::HandPose>> SolveArcoIk(const DecodeContext& context,
                                                       const ArcoIkOptions& options,
                                                       const PitchModelOptions& pitch_options,
                                                       int lead_frames,
                                                       std::vector<FrameContact>* contacts,
                                                       IkStats* stats,
                                                       int num_threads);

}  // namespace arco::refine
