// The published method's choice of string and finger (Jin et al. 2024, section 5 of the
// method in DOMAIN.md section 1), frame by frame:
//  1. candidates on every string whose range holds the frame's pitch (Eq. 2);
//  2. the candidate nearest the hand's WRIST is chosen (as the paper says; the authors'
//     code uses the nearest fingertip instead, DOMAIN.md section 2);
//  3. it is bound to the nearest fingertip (index .. little);
//  4. the binding (string, finger) is kept while the pitch stays within +-binding_cents
//     of both the previous frame and the running mean of the bound run (vibrato), as the
//     authors' code does; otherwise steps 2-3 are repeated.
// Shared with arco (pitch_model.h): unvoiced and low-confidence frames give no contact, an
// open-string pitch gives no finger contact (the authors' code puts a contact at the nut),
// unplayable pitches give none. Unlike arco there is no note segmentation: outlier frames
// and short notes are used as they come. A silence breaks the binding (the authors' code
// carries it across silences). The IK (Eq. 3) is in finger_ik.h.
#pragma once

#include <vector>

#include "arco/refine/contact_annotation.h"
#include "arco/refine/decode_context.h"

namespace arco::refine {

// One FrameContact per frame (before IK: tip distances from the vision hand only).
std::vector<FrameContact> DecodePaper(const DecodeContext& context,
                                      const PaperOptions& options,
                                      const PitchModelOptions& pitch_options);

}  // namespace arco::refine
