// `arco refine RESULT --mode paper|arco|vision`: re-runs only the refinement on a result
// folder written by `arco run` (pipeline/refine_stage.h), e.g. after changing refinement
// options.
#include <cstdio>
#include <memory>
#include <optional>

#include "arco/cli/command.h"
#include "arco/cli/flag_names.h"
#include "arco/cli/number_option.h"
#include "arco/cli/report.h"
#include "arco/pipeline/refine_stage.h"

namespace arco::cli {
namespace {

struct RefineArgs {
  // Bound to the flags directly: the defaults shown by --help are the library's.
  pipeline::RefineStageOptions o;
  std::string mode = "arco";
  std::string joints = hand::FingerIkJointsName(refine::ArcoIkOptions{}.joints);
  bool exact_reach = false;
  bool no_audio_onsets = false;
  bool one_view_lift_test = false;
  // The options as validated when the command line was parsed: RunRefineStage takes them
  // as they are (one validation).
  std::optional<Validated<pipeline::RefineStageOptions>> valid;
};

// The parse-complete step: the named choices into the options, then their Validate().
void ApplyAndValidate(RefineArgs& a) {
  auto mode = refine::ParseRefineMode(a.mode);
  ThrowIfInvalid(mode.status());
  a.o.refine.mode = *mode;
  if (a.joints == "pip_dip") a.o.refine.ik.joints = hand::FingerIkJoints::kPipDip;
  if (a.joints == "all") a.o.refine.ik.joints = hand::FingerIkJoints::kAll;
  if (a.joints == "mcp_flex_pip_dip") a.o.refine.ik.joints = hand::FingerIkJoints::kMcpFlexPipDip;
  a.o.refine.ik.exact_reach = a.exact_reach;
  a.o.refine.decode.audio_onsets = !a.no_audio_onsets;
  a.o.refine.decode.one_view_keep_out_of_reach = !a.one_view_lift_test;
  StatusOr<Validated<pipeline::RefineStageOptions>> valid =
      Validated<pipeline::RefineStageOptions>::Check(a.o);
  if (!valid.ok()) {
    ThrowIfInvalid(Status::Error(WithFlagNames(valid.status().message(), kRefineFlags)));
  }
  a.valid = std::move(valid).value();
}

int RunRefine(const RefineArgs& a) {
  auto summary = pipeline::RunRefineStage(*a.valid);
  if (!summary.ok()) return PrintError(summary.status().message());
  std::printf("%s\nwrote %s/%s/\n",
              FormatRefineSummary(*summary).c_str(),
              a.o.result_dir.c_str(),
              refine::RefineModeName(a.o.refine.mode));
  return 0;
}

std::function<int()> SetupRefine(CLI::App& app) {
  auto* sub = app.add_subcommand(
      "refine", "Re-run only the audio-guided refinement on a result folder of `arco run`");
  auto a = std::make_shared<RefineArgs>();
  refine::RefineOptions& r = a->o.refine;
  sub->add_option("result", a->o.result_dir, "Result folder written by `arco run`")->required();
  sub->add_option("--mode",
                  a->mode,
                  "paper: the published method (wrist-nearest candidate, nearest fingertip, "
                  "+-30 cents binding, PIP/DIP IK); arco: Viterbi decoding and bounded "
                  "MCP/PIP/DIP IK with a lift test; vision: the fitted hand as is")
      ->check(CLI::IsMember({"paper", "arco", "vision"}))
      ->capture_default_str();
  AddNumber(sub,
            "--threads",
            r.num_threads,
            "Worker threads (0 = all cores; results do not depend on it)",
            kThreadsRange)
      ->capture_default_str();
  AddNumber(sub,
            "--min-confidence",
            r.pitch.min_confidence,
            "Pitch confidence below which a frame gets no contact",
            kMinConfidenceRange)
      ->capture_default_str();
  AddNumber(sub,
            "--binding-cents",
            r.paper.binding_cents,
            "paper: keep the finger binding while the pitch stays within this many cents",
            AboveZero(1200))
      ->capture_default_str();
  AddNumber(sub,
            "--max-residual-mm",
            r.ik.max_residual_mm,
            "arco: reject a contact the bounded IK cannot bring the tip within this "
            "distance of (mm)",
            AboveZero(1000))
      ->capture_default_str();
  AddNumber(sub,
            "--max-hand-shift-mm",
            r.ik.max_hand_shift_mm,
            "arco: when the finger alone cannot reach, move the whole hand up to this far "
            "(mm); beyond it the contact is rejected",
            Closed(0, 1000))
      ->capture_default_str();
  sub->add_flag("!--no-distal-first",
                r.ik.distal_first,
                "arco: solve MCP flexion, PIP and DIP together from the start, not PIP and DIP "
                "first (the MCP freed only when they cannot reach)");
  AddNumber(sub,
            "--pip-weight",
            r.ik.pip_weight,
            "arco: weight of the playing finger's PIP keypoint (the mean of its fitted and "
            "triangulated positions) relative to the tip's in the IK (0 = off)",
            refine::kCostWeightRange)
      ->capture_default_str();
  sub->add_flag("--move-hand",
                r.ik.move_hand,
                "arco: move the output hand by the whole-hand shift that makes a contact "
                "reachable (otherwise the shift only decides reachability; the hand stays "
                "where the cameras put it)");
  sub->add_flag("!--reject-unreachable",
                r.ik.keep_unreachable,
                "arco: reject a contact the finger cannot reach even after the hand's move "
                "(uncertain, out_of_reach) instead of keeping the decoded note and finger");
  sub->add_flag("!--semitone-hand-frame",
                r.decode.hand_frame_in_mm,
                "arco decoding: the hand frame's finger spacing in semitones on every "
                "instrument (the former rule), not in mm on the cello and the double bass");
  sub->add_flag("!--no-gap-bridging",
                r.decode.bridge_short_gaps,
                "arco decoding: frames of a short gap between two notes on one string join "
                "the next note only where the fitted fingertip is near its contact (the former "
                "rule), not wherever they hear that note, however unsurely");
  sub->add_flag("!--whole-hand-shift",
                r.ik.detected_hand_shift,
                "arco: move the whole hand by all of the offset its finger cannot reach (the "
                "former rule), not only as far as the triangulated palm says the fit is off");
  AddNumber(sub,
            "--lift-max-mm",
            r.ik.lift_max_distance_mm,
            "arco: reject contacts farther than this from the fitted fingertip (mm; 0 = "
            "the finger's tip-to-PIP length)",
            Closed(0, 1000))
      ->capture_default_str();
  sub->add_option("--joints", a->joints, "arco: free joints of the playing finger")
      ->check(CLI::IsMember({"all", "mcp_flex_pip_dip", "pip_dip"}))
      ->capture_default_str();
  AddNumber(sub,
            "--reference-weight",
            r.ik.reference_weight_mm_per_rad,
            "arco: IK prior toward the fitted angles (mm per rad)",
            refine::kCostWeightRange)
      ->capture_default_str();
  AddNumber(sub,
            "--temporal-weight",
            r.ik.temporal_weight_mm_per_rad,
            "arco: IK prior toward the previous frame's solution (mm per rad)",
            refine::kCostWeightRange)
      ->capture_default_str();
  sub->add_flag("--exact-reach",
                a->exact_reach,
                "arco: the hand IK's exact reach instead of one regularised (least change) solve");
  sub->add_flag("--no-audio-onsets",
                a->no_audio_onsets,
                "arco: assign the frames at note changes by their own pitch only, not by the "
                "onsets of the audio's notes (notes.csv)");
  AddNumber(sub,
            "--onset-tolerance-s",
            r.decode.boundaries.onset_tolerance_s,
            "arco: a frame this long before an audio onset belongs to the new note (s)",
            Closed(0, 10))
      ->capture_default_str();
  AddNumber(sub,
            "--neighbour-shift-frames",
            r.ik.neighbour_shift_frames,
            "arco: a frame the lift test rejected starts from the hand shift of its "
            "accepted neighbours of the same note within this many frames (0: off)",
            Closed(0, 1000))
      ->capture_default_str();
  AddNumber(sub,
            "--straddle-s",
            r.decode.boundaries.straddle_s,
            "arco: a note's frames this soon after its audio onset whose pitch is off "
            "the note's take the note's pitch (s; 0: off)",
            Closed(0, 10))
      ->capture_default_str();
  AddNumber(sub,
            "--normal-weight",
            r.decode.normal_weight,
            "arco decoding: weight of the tip-to-contact distance along the string "
            "plane's normal",
            refine::kCostWeightRange)
      ->capture_default_str();
  AddNumber(sub,
            "--lateral-weight",
            r.decode.lateral_weight,
            "arco decoding: weight of the tip-to-contact distance across the string",
            refine::kCostWeightRange)
      ->capture_default_str();
  AddNumber(sub,
            "--below-margin-mm",
            r.decode.below_margin_mm,
            "arco decoding: a fingertip deeper than this under the string plane counts its "
            "depth beyond it in full (it is beside the fingerboard, not on the string)",
            refine::kCostWeightRange)
      ->capture_default_str();
  AddNumber(sub,
            "--hand-lateral-weight",
            r.decode.hand_lateral_weight,
            "arco decoding: weight of the hand's median fingertip offset across the "
            "strings",
            refine::kCostWeightRange)
      ->capture_default_str();
  AddNumber(sub,
            "--shift-cost",
            r.decode.shift_cost_per_semitone,
            "arco decoding: cost per semitone of hand-position change between notes (mm)",
            refine::kCostWeightRange)
      ->capture_default_str();
  AddNumber(sub,
            "--one-view-max-shift-factor",
            r.decode.one_view_max_shift_factor,
            "arco decoding, one camera: the shift cost times 1 / sin^2 of the angle between the "
            "strings and the camera's ray, at most this (1: as with several cameras)",
            refine::kCostWeightRange)
      ->capture_default_str();
  AddNumber(sub,
            "--one-view-shift-cost-factor",
            r.decode.one_view_shift_cost_factor,
            "arco decoding, one camera: the shift cost times this as well (the hand's place "
            "along the string is partly the first decoding's sound; 1: the view's factor alone)",
            refine::kCostWeightRange)
      ->capture_default_str();
  AddNumber(sub,
            "--one-view-lateral-weight",
            r.decode.one_view_lateral_weight,
            "arco decoding, one camera: --lateral-weight for the candidates compared along "
            "the camera's rays",
            refine::kCostWeightRange)
      ->capture_default_str();
  AddNumber(sub,
            "--one-view-above-margin-mm",
            r.decode.one_view_above_margin_mm,
            "arco decoding, one camera: a fingertip higher than this above the string plane "
            "counts the height beyond it in full (mm)",
            refine::kCostWeightRange)
      ->capture_default_str();
  sub->add_flag("--one-view-lift-test",
                a->one_view_lift_test,
                "arco decoding, one camera: the lift test as with several cameras: a candidate "
                "beyond its reach is infeasible, and a frame whose fingertip is beyond it of "
                "the decided contact becomes uncertain (default: neither; pressed, reason "
                "out_of_reach)");
  sub->add_flag("!--one-view-whole-hand-depth",
                r.one_view_hand_frame,
                "arco, one camera: the hand moved along its rays as a whole by the sound's "
                "depth only (the former rule), not each keypoint by the hand frame");
  AddNumber(sub,
            "--one-view-frame-sigma-mm",
            r.one_view_frame.frame_sigma_mm,
            "arco, one camera: how far (mm) the other fingertips may lie from their places "
            "along the string in the hand frame",
            refine::kFrameSigmaRangeMm)
      ->capture_default_str();
  AddNumber(sub,
            "--one-view-smoothing-s",
            r.one_view_smoothing_s,
            "arco, one camera: hold the refined hand over this many seconds each side in the "
            "instrument's frame (0: off)",
            refine::kOneViewSmoothingRangeS)
      ->capture_default_str();
  AddNumber(sub,
            "--one-view-same-note-weight",
            r.one_view_same_note_weight,
            "arco, one camera: blend a pressed frame's held hand with its median over every "
            "frame playing the same note, finger and string (0: off)",
            refine::kOneViewSameNoteWeightRange)
      ->capture_default_str();
  sub->parse_complete_callback([a] { ApplyAndValidate(*a); });
  return [a]() { return RunRefine(*a); };
}

}  // namespace
ARCO_REGISTER_COMMAND(refine, 55, SetupRefine);
}  // namespace arco::cli
