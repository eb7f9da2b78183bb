// Audio-guided refinement of the left hand: from the pitch to a finger contact to a
// corrected hand (Jin et al. 2024, sections 5-6; DOMAIN.md sections 1, 2, 5).
//
//   PitchAnalysis   pitch_model.h: rest / uncertain / notes, candidates per string (Eq. 2)
//   decoding        paper_decode.h (the paper: per frame, wrist-nearest candidate, nearest
//                   fingertip, +-30 cents binding) or arco_decode.h (Viterbi over
//                   (string, finger) per note)
//   finger IK       finger_ik.h: the playing finger's tip to the contact; the paper's PIP +
//                   DIP, or arco's bounded MCP + PIP + DIP with a prior toward the fitted
//                   pose, temporal smoothing and a lift test
//   transcription   one NoteFingering per note
//
// Inputs are per frame and already in millimetres: the strings (from the smoothed rigid
// instrument pose of that frame, so contacts are never computed on stale strings), the
// vision hand (the fitted left hand, no audio) and the pitch. Frames are independent in
// the IK, which runs in parallel; results do not depend on the thread count.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "arco/hand/hand_model.h"
#include "arco/hand/ik.h"
#include "arco/hand/kinematics.h"
#include "arco/hand/one_view_depth.h"
#include "arco/hand/ray_depth.h"
#include "arco/instrument/instrument_model.h"
#include "arco/instrument/strings.h"
#include "arco/refine/contact_annotation.h"
#include "arco/refine/note_boundaries.h"
#include "arco/refine/pitch_model.h"
#include "arco/util/json_io.h"
#include "arco/util/number_range.h"
#include "arco/util/status.h"

namespace arco::refine {

struct RefineInput {
  // Owned (shared, immutable): an input stays valid however long it is kept or copied.
  std::shared_ptr<const InstrumentModel> instrument;
  hand::HandModel hand_model = hand::HandModel::Default(hand::HandSide::kLeft);
  // Per frame (all three the same length): the strings in the world, index = string - 1
  // (empty: no instrument pose this frame); the fitted left hand; the pitch.
  std::vector<std::vector<StringSegment>> strings_in_world_mm;
  std::vector<std::optional<hand::HandPose>> vision_hand;
  std::vector<FramePitch> pitch;
  double fps = 30.0;
  double a4_hz = 440.0;  // for the transcription's note names and cents
  // The audio layer's notes (audio/notes.h, notes.csv: onsets from the fine pitch track) in
  // time order, and the audio time of frame 0 (pitch.csv's time_s of row 0; frame f is at
  // start_s + f / fps). arco mode assigns the frames at note changes by these onsets
  // (note_boundaries.h); empty: by each frame's own pitch only.
  std::vector<AudioNote> audio_notes;
  double start_s = 0;
  // Per frame (empty, or one per frame): the left hand as the cameras triangulated it (21
  // points, world mm, NaN where missing), before any model fit. arco's IK moves the whole
  // hand toward a contact its joints cannot reach only as far as this detected hand says
  // the fitted one may be off (ArcoIkOptions::contact_sigma_mm). Empty: unknown.
  std::vector<std::optional<hand::HandPointsMm>> detected_left_hand;
  // One camera (track/monocular_lift.h): its centre (world mm). arco then takes the hand's
  // depth from the sound: after a first decoding, the fitted hand is moved along its rays
  // so that the pressing fingertip is as far from the camera as its note's contact
  // (hand/one_view_depth.h, a median over the frames around), and decoded again. Empty:
  // several cameras, whose hand stays where they put it.
  std::optional<Eigen::Vector3d> one_view_camera_centre_mm;
  // Per frame (empty, or one per frame): double stops whose two notes are the pair heard on
  // the two strings the bow rests on (pipeline/refine_stage.h, AddDoubleStops) give the
  // lower of those strings (the higher number, 1 = highest) here, 0 elsewhere. A double
  // stop's lower note is on it: arco's decoding keeps a note whose frames mostly have one
  // on that string (ArcoDecodeOptions::bowed_pair_string). Empty: no such frames.
  std::vector<int> bowed_pair_lower_string;

  // Errors: no instrument, a right-hand model, sizes that differ, fps <= 0, a strings entry
  // with a wrong string count or non-finite ends.
  Status Validate() const;
};

// Every weight and cost of the decoding and the IK priors (mm-equivalents): finite, >= 0,
// and small enough that sums over a clip stay finite.
inline constexpr NumberRange kCostWeightRange = Closed(0, 1e6);

// The paper's choices (paper_decode.h).
struct PaperOptions {
  double binding_cents = 30.0;  // keep the binding while the pitch stays this close
  // IK of Eq. 3: PIP and DIP of the bound finger, a weak pull toward the fitted pose (the
  // paper has none; it only selects among equally good solutions).
  double reference_weight_mm_per_rad = 0.01;
  int max_iterations = 15;
  Status Validate() const;
};

// arco's decoding (arco_decode.h). Costs are in millimetre-equivalents.
struct ArcoDecodeOptions {
  // Hand-to-candidate distance: the component along the front normal of the string plane
  // (a lifted, unloaded finger; detectors see fingers off the string) counts this much.
  double normal_weight = 0.25;
  // ... and the component across the string (within the string plane) this much: which
  // finger plays is told by the position along the string; across it the fitted tips
  // scatter with the detector's lift (the string plane is tilted against the top plate).
  double lateral_weight = 0.25;
  // ... except below the string plane: a fingertip deeper than this under the strings is
  // beside the fingerboard, not on the string (the detector's lift errs upward, a stopping
  // tip sits above its string), and its depth beyond the margin counts in full. On SPD's
  // real take the little finger curled beside the neck, 18-29 mm under the string plane,
  // tied with the ring finger that played (docs/refine.md, "Finger decisions on real
  // playing").
  double below_margin_mm = 10.0;
  // Which string is told by the whole hand: the median over the four fingertips of their
  // offsets across the strings from the contact counts this much.
  double hand_lateral_weight = 1.0;
  // Finger order on the string: index nearest the nut, little nearest the bridge. Other
  // fingertips on the wrong side of the contact by more than the margin cost this much per mm.
  double order_margin_mm = 5.0;
  double order_weight = 0.5;
  double open_cost_mm = 12.0;            // an open string instead of a fingered candidate
  double shift_cost_per_semitone = 1.0;  // hand position change between notes
  // The hand position of a candidate (finger 1's place) from the instrument's hand frame
  // with its spacing in mm where the instrument keeps it so (cello, double bass:
  // HandPositionSemitones in registry/instruments.h): high on the cello's neck a finger
  // covers more than a semitone. false: the frame in semitones everywhere (the former rule).
  // On SPD's real take, a ring finger a whole tone above the second finger at 311 and 346 mm
  // from the nut had been decided as the little finger (docs/refine.md).
  bool hand_frame_in_mm = true;
  double string_cross_cost = 3.0;        // per string crossed between notes
  double same_pitch_change_cost = 40.0;  // other string/finger for (nearly) the same pitch
  double same_pitch_cents = 50.0;
  double rest_gap_s = 0.4;          // a gap this long between notes frees the hand ...
  double rest_factor = 0.3;         // ... and scales the transition costs by this
  double infeasible_cost = 1000.0;  // candidate beyond the lift distance; open with vibrato
  // A note most of whose trusted frames have RefineInput::bowed_pair_lower_string b keeps to
  // string b: its states on other strings are dropped where it can be played on b. The
  // cameras and the pitch alone decide a double stop's lower note like a single note (a
  // double bass's open A1 as the E string's fourth finger, under a bow on the A and D
  // strings).
  bool bowed_pair_string = true;
  // Up to this many untrusted frames (rest, low confidence, ...) right before a stopped
  // note's first trusted frame are pressed too, with the note's first pitch: the finger
  // lands before the bow speaks and the tracker locks on a frame or two late.
  // Only where the fitted fingertip is at most onset_lead_margin_mm farther from the
  // contact than its median over the note (the finger is already there, not on its way).
  int onset_lead_frames = 3;
  double onset_lead_margin_mm = 10.0;
  // A gap of at most onset_lead_frames untrusted frames between a stopped frame on a note's
  // string and the note: its frames that hear the note (within half a semitone, at any
  // confidence) join it without the fitted-tip test (arco_decode.h); false: the test
  // everywhere, the former rule.
  bool bridge_short_gaps = true;
  // The previous note's last (trusted) frame is handed over to the next note when the
  // next finger's fitted tip is nearer its contact by more than this (the sound lags the
  // hand by up to a frame); infinity disables it.
  double handover_margin_mm = 5.0;
  // Transition frames (note_boundary, before_onset: the finger is on its way from the
  // previous note to the next) between two notes' own frames on the same string, each at
  // most glide_frames away: the stopping point moves along the string with the shift, so
  // the contact is at the frame's own pitch when that is trusted (min_confidence) and lies
  // between the two notes' pitches (a glide heard; arco_decode.h). 0: always the note's
  // pitch, the former rule.
  int glide_frames = 3;
  // One camera (RefineInput::one_view_camera_centre_mm): each candidate is compared with
  // the vision hand scaled about the camera's centre until the candidate finger's tip is
  // as far from the camera as the candidate contact (the image unchanged, the depth the
  // candidate's): one view tells where a fingertip is across its ray, not along it.
  // false: the lifted hand as it is (the former rule). No effect with several cameras.
  bool one_view_along_rays = true;
  // One camera: shift_cost_per_semitone times 1 / sin^2 of the angle between the strings
  // and the camera's ray to them, at most this (arco_decode.h, "One camera"); 1: the
  // cameras' cost. No effect with several cameras.
  double one_view_max_shift_factor = 8.0;
  // One camera: the shift cost times this as well, beyond the view's foreshortening. One
  // view's hand is placed along its rays by the sound's depth of a first decoding
  // (RefineOptions::one_view_depth), so the second decoding's emissions measure the hand's
  // place along the string partly from that decoding's own contacts: they tell less than
  // the foreshortening alone says, and the prior that a hand stays weighs more. 2 on the
  // real take (docs/accuracy.md, "One camera: the hand stays where it is, twice"); 1: the
  // foreshortening's factor alone. No effect with several cameras.
  double one_view_shift_cost_factor = 2.0;
  // One camera, along the rays: the weight of the tip-to-contact distance across the string
  // instead of lateral_weight. After the along-ray scaling what is left of tip - contact
  // lies across the camera's ray: across the string it is the image's evidence (the
  // detector's error in the image), not the lifted tip's sideways drift that the cameras'
  // 3D discounts (docs/accuracy.md, "One camera: the image's evidence across the string").
  double one_view_lateral_weight = 1.0;
  // One camera, along the rays: a fingertip higher than this above the string plane counts
  // the height beyond it in full (as one deeper than below_margin_mm under it). A real
  // playing fingertip lies within 13 mm of its contact on 95 % of SPD's frames (DOMAIN.md
  // section 10); along the rays of a view that grazes the string plane a candidate on
  // another string, far along the neck, leaves the tip high above its string, which the
  // normal's discount would let cost a quarter.
  double one_view_above_margin_mm = 15.0;
  // One camera: a frame whose vision fingertip is beyond the lift test's reach of the
  // decided contact keeps the decision (pressed, reason out_of_reach) instead of becoming
  // uncertain. With several cameras a hand that far from the contact says the contact is
  // off (a transition, a wrong note); one camera places the hand by its image alone, and a
  // stretch of bad detections (tens of pixels) leaves it tens of mm away while the sound
  // still names the note: on the real take seen by one camera (30 captures) the strings
  // went 0.968 -> 0.992, the fingers 0.855 -> 0.872, the contact's median unchanged
  // (docs/accuracy.md, "One camera: the sound's decision stands"). Nor does a candidate
  // whose median D (compared along the rays) exceeds the lift distance cost infeasible_cost
  // in the decoding: on the real take's `harsh` captures a poorly fitted hand had put every
  // A-string candidate of a note beyond it and the note on the D string (fingers 0.874 ->
  // 0.877 over 30 captures). false: the lift test as with several cameras. No effect with
  // several cameras.
  bool one_view_keep_out_of_reach = true;
  // Note boundaries from the audio's onsets (note_boundaries.h), when the input has them.
  bool audio_onsets = true;
  NoteBoundaryOptions boundaries;
  Status Validate() const;
};

// arco's IK (finger_ik.h).
struct ArcoIkOptions {
  // The largest set of the playing finger's joints the IK may free. With distal_first
  // (below) they are freed in stages: PIP and DIP first; the MCP's flexion only when they
  // cannot bring the tip within max_residual_mm; its abduction only when that still cannot
  // (a finger that left the string across it). Each later stage moves the PIP keypoint,
  // which the cameras see well, so pip_weight holds it there. Without the staging and the
  // PIP term, free abduction takes the redundancy and drifts to its limits
  // (docs/accuracy.md, the IK ablation).
  hand::FingerIkJoints joints = hand::FingerIkJoints::kAll;
  bool distal_first = true;
  // false: one regularised solve: the priors spread the change over the joints (least
  // change) and leave a small residual (sub-millimetre at these weights); true: the hand
  // IK's exact reach, where the priors only pick among exact solutions and drift along
  // them (worse joints, docs/accuracy.md).
  bool exact_reach = false;
  // The playing finger's PIP keypoint, in position space, toward the mean of its fitted
  // and its triangulated position (the fitted one alone where it is not triangulated),
  // with this weight relative to the tip's (0 = off). A detector's error on a pressing
  // finger is largest at the tip and DIP, and the fit spreads it up the finger; the PIP
  // is what the cameras still see well, so the MCP's angles explain the tip's residual
  // only as far as the PIP allows (docs/refine.md). Acts only with the MCP free
  // (joints other than pip_dip, and not decided by distal_first's first solve).
  double pip_weight = 1.0;
  double reference_weight_mm_per_rad = 1.0;  // prior toward the fitted (vision) pose
  double temporal_weight_mm_per_rad = 4.0;   // toward the previous frame's solution
  // Lift test: a contact farther than this from the fitted fingertip is rejected (0 = the
  // finger's tip-to-PIP length, the dataset authors' cello rule) ...
  double lift_max_distance_mm = 0.0;
  // When the bounded IK leaves the tip farther than max_residual_mm from the contact, the
  // whole hand is translated by the rest if that is at most max_hand_shift_mm (the fitted
  // wrist is off: e.g. a hand fit lagging a shift); otherwise the contact is rejected.
  double max_residual_mm = 3.0;
  double max_hand_shift_mm = 15.0;
  // How far the hand follows: the remaining offset r is taken only where the detected
  // (triangulated) palm says the fitted hand is off, along that displacement d and at most
  // d: shift = d clamp(r.d / |d|^2, 0, 1) (finger_ik.cc, HandShift). A fit that lags a fast
  // shift follows the contact; a hand the cameras and the fit agree on stays where they put
  // it. false, or no detected hand: the whole offset (the former rule).
  bool detected_hand_shift = true;
  // Whether that move is applied to the output hand. false: the move only decides that the
  // contact is reachable by a hand where the cameras saw it (the note, string and finger
  // stand, reason hand_shifted); the hand stays where the fit put it and the finger goes
  // as near as its joints reach. On the real take the move made the wrist, the MCPs and
  // the other fingers worse than vision (docs/accuracy.md, "A real take").
  bool move_hand = false;
  // A contact still farther than max_hand_shift_mm after the IK and the hand's move: true
  // keeps the decoded note, string and finger (state pressed, reason out_of_reach) with the
  // hand as below (stretch_unreachable); false rejects the contact (state uncertain) and
  // leaves the fitted hand, the former lift test.
  bool keep_unreachable = true;
  // Such a kept, unreachable contact: false leaves the whole fitted hand, the finger as the
  // cameras saw it (the contact or the model is off, not that finger); true moves the
  // finger as near as its joints reach (the former rule: on the real take it made the
  // playing finger's PIP, DIP and tip worse than vision on those frames).
  bool stretch_unreachable = false;
  // Transition frames (reasons note_boundary, before_onset: the hand moves from one note
  // to the next, the contact is where the string is stopped meanwhile, arco_decode.h): the
  // playing finger's DIP keypoint is held toward the mean of its fitted and triangulated
  // position with this weight relative to the tip's (0 = off), as pip_weight holds the PIP.
  // Unheld, the finger solved onto those contacts made the DIP worse than vision on the
  // real take (docs/accuracy.md, "A real take"); on a note's own frames the contact is
  // trusted and the DIP is not held.
  double transition_dip_weight = 1.0;
  // A frame the lift test rejected inside a note starts from the fitted hand moved by the
  // whole-hand shift of its nearest accepted frames of the same note, string and finger
  // within this many frames (the fitted hand lags fast shifts); 0: off.
  int neighbour_shift_frames = 2;
  int max_iterations = 15;
  Status Validate() const;
};

// One camera: the pressed frames' hands placed along their rays by the hand frame
// (hand_frame_depth.h says why and how).
inline constexpr NumberRange kFrameSigmaRangeMm = AboveZero(1000);
inline constexpr NumberRange kOneViewSmoothingRangeS = Closed(0, 10);
inline constexpr NumberRange kOneViewSameNoteWeightRange = Closed(0, 1);
struct HandFrameDepthOptions {
  double tip_sigma_mm = 5.0;  // (0, 100]: the pressing fingertip's distance from the camera
  double frame_sigma_mm =
      10.0;  // kFrameSigmaRangeMm: the other fingertips' places along the string
  hand::RayDepthOptions rays;
  Status Validate() const;
};

struct RefineOptions {
  RefineMode mode = RefineMode::kArco;
  PitchModelOptions pitch;
  PaperOptions paper;
  ArcoDecodeOptions decode;
  ArcoIkOptions ik;
  hand::OneViewDepthOptions one_view_depth;  // RefineInput::one_view_camera_centre_mm
  // One camera, arco: after the decoding, each pressed frame's vision hand has its
  // keypoints moved along their rays by the hand frame (hand_frame_depth.h: the pressing
  // fingertip as far from the camera as the contact, the other fingertips at their places
  // along the string), before the IK. false: the hand as the sound's depth moved it (the
  // former rule). No effect with several cameras.
  bool one_view_hand_frame = true;
  HandFrameDepthOptions one_view_frame;
  // One camera, arco: the refined hand held over this many seconds each side in the
  // instrument's frame (one_view_smoothing.h: medians of the wrist's place and the joint
  // angles, the average wrist rotation; a pressed frame's playing fingertip kept where
  // the IK put it). kOneViewSmoothingRangeS; 0: off (the former rule). No effect with
  // several cameras.
  double one_view_smoothing_s = 0.2;
  // One camera, arco: with the hand held (above), a pressed frame's keypoints blended with
  // this weight with their median over every frame of the take that plays the same note
  // with the same finger on the same string (one_view_smoothing.h).
  // kOneViewSameNoteWeightRange; 0: off. No effect with several cameras or without the hold.
  double one_view_same_note_weight = 0.4;
  int num_threads = 0;  // 0 = all cores; results do not depend on it
  Status Validate() const;
};

struct RefineSummary {
  RefineMode mode = RefineMode::kArco;
  int frames = 0;
  int frames_with_hand = 0;
  int pressed = 0, open_string = 0, rest = 0, uncertain = 0;
  int uncertain_by_reason[kNumContactReasons] = {};  // index = ContactReason
  int notes = 0, usable_notes = 0;
  int corrected_frames = 0;  // pressed frames whose finger was moved by the IK
  int rejected_out_of_reach = 0;
  int hand_shifted = 0;   // corrected frames that needed a whole-hand shift
  int before_onset = 0;   // pressed frames added before a note's detected onset
  int note_boundary = 0;  // pressed frames placed in their note by the audio's onsets
  double mean_tip_distance_vision_mm = kNaN;   // over corrected frames
  double mean_tip_distance_refined_mm = kNaN;  // over corrected frames
  double max_tip_distance_refined_mm = kNaN;
  int ik_solves = 0, ik_iterations = 0, ik_not_converged = 0;
  int joint_limit_violations = 0;  // refined poses outside the limits (must stay 0)
};

struct RefineResult {
  std::vector<std::optional<hand::HandPose>> hand;  // refined left hand per frame
  std::vector<FrameContact> contacts;               // empty for kVision
  std::vector<NoteFingering> fingering;             // empty for kVision
  PitchAnalysis analysis;
  RefineSummary summary;
};

// Throws std::invalid_argument for invalid input or options (Validate() messages).
RefineResult Refine(const RefineInput& input, const RefineOptions& options);

// The options as the refinement applies them, recorded with a method's result: mode,
// min_confidence, binding_cents, ik_joints (the paper always solves PIP and DIP),
// max_residual_mm, audio_onsets (arco only), num_threads, and every field of the nested
// options as given: "pitch", "paper", "decode" (with "boundaries"), "ik".
Json ToJson(const RefineOptions& options);

// The counts and distances of a refinement recorded with a method's result (mean tip
// distances null when NaN).
Json ToJson(const RefineSummary& summary);

}  // namespace arco::refine
