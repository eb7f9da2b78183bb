#include "arco/refine/refine.h"

#include <cmath>
#include <stdexcept>

#include "arco/refine/arco_decode.h"
#include "arco/refine/decode_context.h"
#include "arco/refine/finger_ik.h"
#include "arco/refine/hand_frame_depth.h"
#include "arco/refine/one_view_smoothing.h"
#include "arco/refine/paper_decode.h"
#include "arco/refine/transcription.h"

namespace arco::refine {
namespace {

bool Finite(double v) { return std::isfinite(v); }

void ThrowIfError(const Status& status) {
  if (!status.ok()) throw std::invalid_argument(status.message());
}

// Lift distance per finger (ArcoIkOptions::lift_max_distance_mm, 0 = tip-to-PIP length).
std::array<double, 5> LiftMaxMm(const hand::HandModel& model, const ArcoIkOptions& options) {
  std::array<double, 5> out{};
  for (int k = 1; k <= 4; ++k) {
    const hand::Finger finger = static_cast<hand::Finger>(k);
    out[static_cast<size_t>(k)] = options.lift_max_distance_mm > 0
                                      ? options.lift_max_distance_mm
                                      : model.bone_length_mm(hand::KeypointIndex(finger, 2)) +
                                            model.bone_length_mm(hand::KeypointIndex(finger, 3));
  }
  return out;
}

RefineSummary Summarise(RefineMode mode,
                        const RefineInput& input,
                        const RefineResult& result,
                        const IkStats& ik) {
  RefineSummary s;
  s.mode = mode;
  s.frames = static_cast<int>(input.pitch.size());
  for (const auto& h : input.vision_hand) s.frames_with_hand += h.has_value() ? 1 : 0;
  s.notes = static_cast<int>(result.analysis.notes.size());
  for (const NoteSpan& n : result.analysis.notes) s.usable_notes += n.usable ? 1 : 0;
  double sum_vision = 0, sum_refined = 0;
  for (const FrameContact& c : result.contacts) {
    switch (c.state) {
      case ContactState::kPressed:
        ++s.pressed;
        break;
      case ContactState::kOpenString:
        ++s.open_string;
        break;
      case ContactState::kRest:
        ++s.rest;
        break;
      case ContactState::kUncertain:
        ++s.uncertain;
        ++s.uncertain_by_reason[static_cast<int>(c.reason)];
        break;
    }
    if (c.reason == ContactReason::kOutOfReach) ++s.rejected_out_of_reach;
    if (c.reason == ContactReason::kHandShifted) ++s.hand_shifted;
    if (c.reason == ContactReason::kBeforeOnset) ++s.before_onset;
    if (c.pressed() && c.reason == ContactReason::kNoteBoundary) ++s.note_boundary;
    if (c.pressed() && Finite(c.tip_distance_refined_mm)) {
      ++s.corrected_frames;
      sum_vision += c.tip_distance_vision_mm;
      sum_refined += c.tip_distance_refined_mm;
      if (!(c.tip_distance_refined_mm <= s.max_tip_distance_refined_mm)) {
        s.max_tip_distance_refined_mm = c.tip_distance_refined_mm;
      }
    }
  }
  if (s.corrected_frames > 0) {
    s.mean_tip_distance_vision_mm = sum_vision / s.corrected_frames;
    s.mean_tip_distance_refined_mm = sum_refined / s.corrected_frames;
  }
  s.ik_solves = ik.solves;
  s.ik_iterations = ik.iterations;
  s.ik_not_converged = ik.not_converged;
  for (const auto& h : result.hand) {
    if (h) s.joint_limit_violations += hand::CountLimitViolations(input.hand_model, *h);
  }
  return s;
}

}  // namespace

Status RefineInput::Validate() const {
  if (instrument == nullptr) return Status::Error("refine input: no instrument model");
  if (hand_model.side() != hand::HandSide::kLeft) {
    return Status::Error("refine input: the hand model must be a left hand");
  }
  const size_t n = pitch.size();
  if (strings_in_world_mm.size() != n || vision_hand.size() != n) {
    return Status::Error("refine input: " + std::to_string(n) + " pitch frames but " +
                         std::to_string(strings_in_world_mm.size()) + " string frames and " +
                         std::to_string(vision_hand.size()) + " hand frames");
  }
  for (size_t f = 0; f < n; ++f) {
    const size_t count = strings_in_world_mm[f].size();
    if (count != 0 && static_cast<int>(count) != instrument->num_strings()) {
      return Status::Error("refine input: frame " + std::to_string(f) + " has " +
                           std::to_string(count) + " strings, the " + instrument->name() + " has " +
                           std::to_string(instrument->num_strings()));
    }
  }
  if (one_view_camera_centre_mm && !one_view_camera_centre_mm->allFinite())
    return Status::Error("refine input: the one camera's centre is not finite");
  if (!detected_left_hand.empty() && detected_left_hand.size() != n) {
    return Status::Error("refine input: " + std::to_string(detected_left_hand.size()) +
                         " detected hand frames for " + std::to_string(n) + " frames");
  }
  if (!bowed_pair_lower_string.empty() && bowed_pair_lower_string.size() != n) {
    return Status::Error("refine input: " + std::to_string(bowed_pair_lower_string.size()) +
                         " bowed-pair frames for " + std::to_string(n) + " frames");
  }
  for (const int b : bowed_pair_lower_string) {
    if (b < 0 || b > instrument->num_strings()) {
      return Status::Error("refine input: a bowed pair's lower string " + std::to_string(b) +
                           " is not 0 or a string of the " + instrument->name());
    }
  }
  if (!(fps > 0 && Finite(fps))) return Status::Error("refine input: fps must be > 0");
  if (!(a4_hz > 0 && Finite(a4_hz))) return Status::Error("refine input: a4_hz must be > 0");
  if (!Finite(start_s)) return Status::Error("refine input: start_s must be finite");
  for (size_t i = 0; i < audio_notes.size(); ++i) {
    const AudioNote& a = audio_notes[i];
    if (!(Finite(a.onset_s) && Finite(a.offset_s) && a.offset_s >= a.onset_s && a.f0_hz > 0 &&
          Finite(a.f0_hz))) {
      return Status::Error("refine input: audio note " + std::to_string(i) +
                           " needs finite onset <= offset and f0 > 0");
    }
    if (i > 0 && a.onset_s < audio_notes[i - 1].onset_s) {
      return Status::Error("refine input: audio notes must be in time order (note " +
                           std::to_string(i) + ")");
    }
  }
  return Status::Ok();
}

Status PaperOptions::Validate() const {
  if (!(binding_cents > 0 && Finite(binding_cents))) {
    return Status::Error("paper options: binding_cents must be > 0");
  }
  if (!(reference_weight_mm_per_rad >= 0 && Finite(reference_weight_mm_per_rad))) {
    return Status::Error("paper options: reference_weight_mm_per_rad must be >= 0");
  }
  if (max_iterations < 1) return Status::Error("paper options: max_iterations must be >= 1");
  return Status::Ok();
}

Status ArcoDecodeOptions::Validate() const {
  const std::pair<const char*, double> values[] = {
      {"normal_weight", normal_weight},
      {"lateral_weight", lateral_weight},
      {"hand_lateral_weight", hand_lateral_weight},
      {"below_margin_mm", below_margin_mm},
      {"order_margin_mm", order_margin_mm},
      {"order_weight", order_weight},
      {"open_cost_mm", open_cost_mm},
      {"shift_cost_per_semitone", shift_cost_per_semitone},
      {"string_cross_cost", string_cross_cost},
      {"same_pitch_change_cost", same_pitch_change_cost},
      {"same_pitch_cents", same_pitch_cents},
      {"rest_gap_s", rest_gap_s},
      {"rest_factor", rest_factor},
      {"infeasible_cost", infeasible_cost},
      {"onset_lead_margin_mm", onset_lead_margin_mm},
      {"one_view_max_shift_factor", one_view_max_shift_factor},
      {"one_view_shift_cost_factor", one_view_shift_cost_factor},
      {"one_view_lateral_weight", one_view_lateral_weight},
      {"one_view_above_margin_mm", one_view_above_margin_mm}};
  for (const auto& [name, value] : values) {
    ARCO_RETURN_IF_ERROR(
        CheckInRange(name, value, kCostWeightRange).WithContext("arco decode options"));
  }
  if (!(handover_margin_mm >= 0)) {
    return Status::Error("arco decode options: handover_margin_mm must be >= 0 (infinity: off)");
  }
  if (onset_lead_frames < 0)
    return Status::Error("arco decode options: onset_lead_frames must be >= 0");
  if (glide_frames < 0) return Status::Error("arco decode options: glide_frames must be >= 0");
  if (!(boundaries.onset_tolerance_s >= 0 && Finite(boundaries.onset_tolerance_s))) {
    return Status::Error("arco decode options: onset_tolerance_s must be finite and >= 0");
  }
  if (!(boundaries.straddle_s >= 0 && Finite(boundaries.straddle_s) &&
        boundaries.straddle_cents >= 0 && Finite(boundaries.straddle_cents))) {
    return Status::Error("arco decode options: straddle_s and straddle_cents must be >= 0");
  }
  if (!(boundaries.match_cents > 0 && Finite(boundaries.match_cents))) {
    return Status::Error("arco decode options: match_cents must be > 0");
  }
  return Status::Ok();
}

Status ArcoIkOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(
      CheckInRange("reference_weight_mm_per_rad", reference_weight_mm_per_rad, kCostWeightRange)
          .WithContext("arco IK options"));
  ARCO_RETURN_IF_ERROR(
      CheckInRange("temporal_weight_mm_per_rad", temporal_weight_mm_per_rad, kCostWeightRange)
          .WithContext("arco IK options"));
  if (!(lift_max_distance_mm >= 0 && Finite(lift_max_distance_mm))) {
    return Status::Error("arco IK options: lift_max_distance_mm must be >= 0 (0 = automatic)");
  }
  if (!(max_residual_mm > 0 && Finite(max_residual_mm))) {
    return Status::Error("arco IK options: max_residual_mm must be > 0");
  }
  if (!(max_hand_shift_mm >= 0 && Finite(max_hand_shift_mm))) {
    return Status::Error("arco IK options: max_hand_shift_mm must be >= 0");
  }
  ARCO_RETURN_IF_ERROR(
      CheckInRange("pip_weight", pip_weight, kCostWeightRange).WithContext("arco IK options"));
  ARCO_RETURN_IF_ERROR(
      CheckInRange("transition_dip_weight", transition_dip_weight, kCostWeightRange)
          .WithContext("arco IK options"));
  if (max_iterations < 1) return Status::Error("arco IK options: max_iterations must be >= 1");
  if (neighbour_shift_frames < 0) {
    return Status::Error("arco IK options: neighbour_shift_frames must be >= 0");
  }
  return Status::Ok();
}

Status RefineOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(pitch.Validate());
  ARCO_RETURN_IF_ERROR(paper.Validate());
  ARCO_RETURN_IF_ERROR(decode.Validate());
  ARCO_RETURN_IF_ERROR(ik.Validate());
  ARCO_RETURN_IF_ERROR(one_view_depth.Validate().WithContext("refine options: one_view_depth"));
  ARCO_RETURN_IF_ERROR(one_view_frame.Validate().WithContext("refine options: one_view_frame"));
  ARCO_RETURN_IF_ERROR(
      CheckInRange("one_view_smoothing_s", one_view_smoothing_s, kOneViewSmoothingRangeS)
          .WithContext("refine options"));
  ARCO_RETURN_IF_ERROR(CheckInRange("one_view_same_note_weight",
                                    one_view_same_note_weight,
                                    kOneViewSameNoteWeightRange)
                           .WithContext("refine options"));
  if (num_threads < 0) return Status::Error("refine options: num_threads must be >= 0");
  return Status::Ok();
}

RefineResult Refine(const RefineInput& input, const RefineOptions& options) {
  ThrowIfError(input.Validate());
  ThrowIfError(options.Validate());
  RefineResult result;
  IkStats ik;
  if (options.mode == RefineMode::kVision) {
    result.hand = input.vision_hand;
    result.summary = Summarise(options.mode, input, result, ik);
    return result;
  }
  result.analysis = AnalysePitch(input.pitch, options.pitch);
  if (options.mode == RefineMode::kArco && options.decode.audio_onsets) {
    ApplyAudioNoteBoundaries(input.audio_notes,
                             input.start_s,
                             input.fps,
                             input.pitch,
                             options.pitch,
                             options.decode.boundaries,
                             &result.analysis);
  }
  const DecodeContext context = MakeDecodeContext(input, result.analysis, options.num_threads);
  if (options.mode == RefineMode::kPaper) {
    result.contacts = DecodePaper(context, options.paper, options.pitch);
    result.hand = SolvePaperIk(context, options.paper, &result.contacts, &ik, options.num_threads);
  } else {
    result.contacts = DecodeArco(context,
                                 options.decode,
                                 options.pitch,
                                 LiftMaxMm(input.hand_model, options.ik),
                                 options.num_threads);
    // One camera: the hand's depth from the sound, then the decoding again.
    RefineInput moved;
    DecodeContext moved_context;
    const DecodeContext* ik_context = &context;
    if (input.one_view_camera_centre_mm) {
      const Eigen::Vector3d& centre = *input.one_view_camera_centre_mm;
      std::vector<double> shift(input.pitch.size(), kNaN);
      for (size_t f = 0; f < shift.size(); ++f) {
        const FrameContact& c = result.contacts[f];
        const auto& tips = context.vision_points[f];
        if (!c.pressed() || c.finger < 1 || c.finger > 4 || !tips ||
            !c.point_in_world_mm.allFinite())
          continue;
        const Eigen::Vector3d& tip =
            (*tips)[hand::TipKeypoint(static_cast<hand::Finger>(c.finger))];
        shift[f] = (c.point_in_world_mm - centre).norm() - (tip - centre).norm();
      }
      moved = input;
      ThrowIfError(
          hand::MoveHandsAlongRays(centre, shift, options.one_view_depth, &moved.vision_hand)
              .status());
      moved_context = MakeDecodeContext(moved, result.analysis, options.num_threads);
      result.contacts = DecodeArco(moved_context,
                                   options.decode,
                                   options.pitch,
                                   LiftMaxMm(input.hand_model, options.ik),
                                   options.num_threads);
      // The hand frame's depth (hand_frame_depth.h), then the context the IK starts from.
      if (options.one_view_hand_frame) {
        PlaceHandsInTheirFrame(moved_context,
                               result.contacts,
                               centre,
                               options.one_view_frame,
                               options.num_threads,
                               &moved.vision_hand);
        moved_context = MakeDecodeContext(moved, result.analysis, options.num_threads);
      }
      ik_context = &moved_context;
    }
    result.hand = SolveArcoIk(*ik_context,
                              options.ik,
                              options.pitch,
                              options.decode.onset_lead_frames,
                              &result.contacts,
                              &ik,
                              options.num_threads);
    if (input.one_view_camera_centre_mm && options.one_view_smoothing_s > 0) {
      const int window = static_cast<int>(std::lround(options.one_view_smoothing_s * input.fps));
      SmoothHandsInInstrumentFrame(*ik_context,
                                   result.contacts,
                                   window,
                                   options.one_view_same_note_weight,
                                   options.num_threads,
                                   &result.hand);
    }
  }
  result.fingering =
      Transcribe(*input.instrument, result.analysis, result.contacts, input.fps, input.a4_hz);
  result.summary = Summarise(options.mode, input, result, ik);
  return result;
}

Json ToJson(const RefineOptions& o) {
  return {{"mode", RefineModeName(o.mode)},
          {"min_confidence", o.pitch.min_confidence},
          {"binding_cents", o.paper.binding_cents},
          {"ik_joints",
           hand::FingerIkJointsName(o.mode == RefineMode::kPaper ? hand::FingerIkJoints::kPipDip
                                                                 : o.ik.joints)},
          {"max_residual_mm", o.ik.max_residual_mm},
          {"audio_onsets", o.mode == RefineMode::kArco && o.decode.audio_onsets},
          {"num_threads", o.num_threads},
          {"one_view_depth", {{"window_frames", o.one_view_depth.window_frames}}},
          {"one_view_hand_frame", o.one_view_hand_frame},
          {"one_view_smoothing_s", o.one_view_smoothing_s},
          {"one_view_same_note_weight", o.one_view_same_note_weight},
          {"one_view_frame",
           {{"tip_sigma_mm", o.one_view_frame.tip_sigma_mm},
            {"frame_sigma_mm", o.one_view_frame.frame_sigma_mm},
            {"bone_sigma_mm", o.one_view_frame.rays.bone_sigma_mm},
            {"stay_sigma_mm", o.one_view_frame.rays.stay_sigma_mm},
            {"max_iterations", o.one_view_frame.rays.max_iterations}}},
          {"pitch",
           {{"min_confidence", o.pitch.min_confidence},
            {"min_confidence_in_note", o.pitch.min_confidence_in_note},
            {"note_change_cents", o.pitch.note_change_cents},
            {"note_change_frames", o.pitch.note_change_frames},
            {"median_window_frames", o.pitch.median_window_frames},
            {"min_note_frames", o.pitch.min_note_frames},
            {"max_outlier_fraction", o.pitch.max_outlier_fraction},
            {"jump_cents", o.pitch.jump_cents},
            {"jump_window_frames", o.pitch.jump_window_frames},
            {"max_jumps_in_window", o.pitch.max_jumps_in_window},
            {"vibrato_min_cents", o.pitch.vibrato_min_cents},
            {"contact",
             {{"open_tolerance_cents", o.pitch.contact.open_tolerance_cents},
              {"range_tolerance_cents", o.pitch.contact.range_tolerance_cents},
              {"physical_correction", o.pitch.contact.physical_correction}}}}},
          {"paper",
           {{"binding_cents", o.paper.binding_cents},
            {"reference_weight_mm_per_rad", o.paper.reference_weight_mm_per_rad},
            {"max_iterations", o.paper.max_iterations}}},
          {"decode",
           {{"normal_weight", o.decode.normal_weight},
            {"lateral_weight", o.decode.lateral_weight},
            {"below_margin_mm", o.decode.below_margin_mm},
            {"hand_lateral_weight", o.decode.hand_lateral_weight},
            {"order_margin_mm", o.decode.order_margin_mm},
            {"order_weight", o.decode.order_weight},
            {"open_cost_mm", o.decode.open_cost_mm},
            {"shift_cost_per_semitone", o.decode.shift_cost_per_semitone},
            {"hand_frame_in_mm", o.decode.hand_frame_in_mm},
            {"string_cross_cost", o.decode.string_cross_cost},
            {"same_pitch_change_cost", o.decode.same_pitch_change_cost},
            {"same_pitch_cents", o.decode.same_pitch_cents},
            {"rest_gap_s", o.decode.rest_gap_s},
            {"rest_factor", o.decode.rest_factor},
            {"infeasible_cost", o.decode.infeasible_cost},
            {"onset_lead_frames", o.decode.onset_lead_frames},
            {"onset_lead_margin_mm", o.decode.onset_lead_margin_mm},
            {"bridge_short_gaps", o.decode.bridge_short_gaps},
            {"handover_margin_mm", JsonFromDouble(o.decode.handover_margin_mm)},  // inf: off
            {"glide_frames", o.decode.glide_frames},
            {"audio_onsets", o.decode.audio_onsets},
            {"one_view_along_rays", o.decode.one_view_along_rays},
            {"one_view_max_shift_factor", o.decode.one_view_max_shift_factor},
            {"one_view_shift_cost_factor", o.decode.one_view_shift_cost_factor},
            {"one_view_lateral_weight", o.decode.one_view_lateral_weight},
            {"one_view_above_margin_mm", o.decode.one_view_above_margin_mm},
            {"one_view_keep_out_of_reach", o.decode.one_view_keep_out_of_reach},
            {"bowed_pair_string", o.decode.bowed_pair_string},
            {"boundaries",
             {{"onset_tolerance_s", o.decode.boundaries.onset_tolerance_s},
              {"match_cents", o.decode.boundaries.match_cents},
              {"straddle_s", o.decode.boundaries.straddle_s},
              {"straddle_cents", o.decode.boundaries.straddle_cents}}}}},
          {"ik",
           {{"joints", hand::FingerIkJointsName(o.ik.joints)},
            {"exact_reach", o.ik.exact_reach},
            {"reference_weight_mm_per_rad", o.ik.reference_weight_mm_per_rad},
            {"temporal_weight_mm_per_rad", o.ik.temporal_weight_mm_per_rad},
            {"lift_max_distance_mm", o.ik.lift_max_distance_mm},
            {"max_residual_mm", o.ik.max_residual_mm},
            {"max_hand_shift_mm", o.ik.max_hand_shift_mm},
            {"detected_hand_shift", o.ik.detected_hand_shift},
            {"move_hand", o.ik.move_hand},
            {"keep_unreachable", o.ik.keep_unreachable},
            {"stretch_unreachable", o.ik.stretch_unreachable},
            {"transition_dip_weight", o.ik.transition_dip_weight},
            {"distal_first", o.ik.distal_first},
            {"pip_weight", o.ik.pip_weight},
            {"neighbour_shift_frames", o.ik.neighbour_shift_frames},
            {"max_iterations", o.ik.max_iterations}}}};
}

Json ToJson(const RefineSummary& s) {
  return {{"frames", s.frames},
          {"frames_with_hand", s.frames_with_hand},
          {"pressed", s.pressed},
          {"open_string", s.open_string},
          {"rest", s.rest},
          {"uncertain", s.uncertain},
          {"notes", s.notes},
          {"usable_notes", s.usable_notes},
          {"corrected_frames", s.corrected_frames},
          {"rejected_out_of_reach", s.rejected_out_of_reach},
          {"before_onset", s.before_onset},
          {"note_boundary", s.note_boundary},
          {"mean_tip_distance_vision_mm", JsonFromDouble(s.mean_tip_distance_vision_mm)},
          {"mean_tip_distance_refined_mm", JsonFromDouble(s.mean_tip_distance_refined_mm)},
          {"joint_limit_violations", s.joint_limit_violations}};
}

}  // namespace arco::refine
