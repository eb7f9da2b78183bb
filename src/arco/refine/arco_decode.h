// arco's choice of string and finger: a Viterbi decode over the notes of the audio
// (pitch_model.h), with one state per (string, finger) candidate and one per matching open
// string, so the decision is made once per note from all of its frames and a single noisy
// frame cannot flip the string.
//
// Emission cost of a note for state (string s, finger k), in mm-equivalents: the median
// over the note's trusted frames (not boundary frames, note_boundaries.h) of
//   D = sqrt(a^2 + (w_l l)^2 + (w_n n)^2 + b^2 + (w_h H)^2),  (a, l, n) = tip_k - contact on
//       that frame's string s along the string, across it and along the string plane's
//       normal (positive away from the fingerboard); b = max(0, -n - below_margin_mm), the
//       depth under the strings beyond a margin, counted in full (a tip there is beside
//       the fingerboard: a stopping tip sits above its string, the detector's lift errs up);
//       H = the median over the four fingertips of their signed offsets across the
//       strings from the contact. Which finger plays is told along the string; the tip's
//       own l and n are mostly detector error (a lifted, unloaded finger that the hand fit
//       follows partly sideways: w_l = lateral_weight, w_n = normal_weight); which string
//       is told by the whole hand (w_h = hand_lateral_weight: one finger's error cannot
//       move the median),
// plus order_weight x the median finger-order violation: the other fingertips projected on
// the string must lie on the nut side of the contact for lower fingers (index is nearest
// the nut) and on the bridge side for higher ones, within order_margin_mm. A state whose
// median D exceeds the lift distance costs infeasible_cost more. An open string costs
// open_cost_mm, plus infeasible_cost when the note vibrates (an open string cannot).
//
// Transition between consecutive notes: none for the same state; for (nearly) the same
// pitch, same_pitch_change_cost for any change; otherwise shift_cost_per_semitone x the
// change of hand position (semitones of finger 1 above the open string, from the finger's
// offset in the instrument's hand frame, in mm on the cello and the double bass with
// hand_frame_in_mm: HandPositionSemitones) + string_cross_cost x strings crossed; scaled by
// rest_factor after a gap of rest_gap_s or more. Ties go to the lower state index.
//
// Boundary frames (the audio's onsets place them in a note, their own pitch is not
// trusted) get the note's contact at the note's median pitch (kNoteBoundary).
// Up to onset_lead_frames untrusted frames right before a stopped note's first trusted
// frame get the note's contact too (kBeforeOnset): the finger lands before the sound.
// With the audio's onsets, frames still with the previous note are not handed over.
// Only where the fitted tip is no more than onset_lead_margin_mm farther from the contact
// than its median over the note (the hand is already in place), except in a short gap
// (bridge_short_gaps): when every frame between a stopped frame on the note's string and
// the note is untrusted and there are at most onset_lead_frames of them, those whose own
// pitch, however unsure, is within half a semitone of the note's first trusted frame join
// the note whatever the fitted hand says. The tracker hears the note coming; a poorly
// fitted hand (the real take's harsh detector errors) would otherwise leave them
// uncertain. A gap that is unvoiced, or hears another note (a short note the tracker
// missed, on another string), keeps the fitted-tip test.
// Glides: a transition frame (kNoteBoundary, kBeforeOnset) with a frame of another note on
// either side within glide_frames (the nearest non-transition pressed frames, both on its
// string) is where the stopping point moves from one note's place to the other's: its
// contact is at the frame's own pitch when that is trusted (min_confidence) and between the
// two frames' pitches: the glide is heard, the string is stopped there. Otherwise the
// note's contact stays (an untrusted pitch says nothing; the finger may have landed). On
// a real take (SPD cello01) the note's pitch put such frames 14-18 mm from SPD's contact
// (docs/refine.md).
// One camera (RefineInput::one_view_camera_centre_mm): candidates are compared along the
// camera's rays (ArcoDecodeOptions::one_view_along_rays), and the shift cost is multiplied
// by 1 / sin^2 of the angle between the strings and the camera's ray to their middle (the
// median over the frames), at most one_view_max_shift_factor: a move along the strings is
// foreshortened by sin theta in the view, so the view tells sin^2 theta of what several do
// about the hand's place along the string, and the prior that the hand stays weighs more;
// times one_view_shift_cost_factor, as the second decoding's hand was placed along its rays
// by the first decoding's sound (refine.h).
#pragma once

#include <array>
#include <limits>
#include <vector>

#include "arco/refine/contact_annotation.h"
#include "arco/refine/decode_context.h"

namespace arco::refine {

// The hand position of a state uses FingerOffsetSemitones (registry/instruments.h).

// One frame's emission of finger k (1..4) at a candidate contact on the string whose frame
// is `sf`: *distance = D above, *order = the finger-order violation (mm, before
// order_weight). `points`: the vision hand in world mm.
void FrameCosts(const hand::HandPointsMm& points,
                const StringFrame& sf,
                const Eigen::Vector3d& contact,
                int finger,
                const ArcoDecodeOptions& options,
                double* distance,
                double* order,
                double above_margin_mm = std::numeric_limits<double>::infinity());

// lift_max_mm[k] for finger k = 1..4 (entry 0 unused). One FrameContact per frame (before
// IK). Frames of a note whose contact fails the lift test come back kUncertain with
// kOutOfReach, the decoded string and finger kept for information.
std::vector<FrameContact> DecodeArco(const DecodeContext& context,
                                     const ArcoDecodeOptions& options,
                                     const PitchModelOptions& pitch_options,
                                     const std::array<double, 5>& lift_max_mm,
                                     int num_threads);

}  // namespace arco::refine
