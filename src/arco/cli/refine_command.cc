// `arco refine RESULT --mode paper|arco|vision`: re-runs only the refinement on a result
// folder written by `arco run` (pipeline/refine_stage.h), e.g. after changing refinement
// options.
#include <cstdio>
#include <memory>

#include "arco/cli/command.h"
#include "arco/cli/report.h"
#include "arco/pipeline/refine_stage.h"

namespace arco::cli {
namespace {

struct RefineArgs {
  std::string result;
  std::string mode = "arco";
  int threads = 0;
  double min_confidence = 0.5;
  double binding_cents = 30.0;
  double max_residual_mm = 3.0;
  double lift_max_mm = 0.0;
  double max_hand_shift_mm = 15.0;
  std::string joints = "mcp_flex_pip_dip";
  double reference_weight = -1;  // < 0: the default
  double temporal_weight = -1;
  bool exact_reach = false;
  bool no_audio_onsets = false;
  double onset_tolerance_s = -1;  // < 0: the default
  double straddle_s = -1;
  int neighbour_shift_frames = -1;
  double normal_weight = -1;
  double lateral_weight = -1;
  double hand_lateral_weight = -1;
  double shift_cost = -1;
};

int RunRefine(const RefineArgs& a) {
  pipeline::RefineStageOptions o;
  o.result_dir = a.result;
  auto mode = refine::ParseRefineMode(a.mode);
  if (!mode.ok()) return PrintError(mode.status().message());
  o.refine.mode = *mode;
  o.refine.num_threads = a.threads;
  o.refine.pitch.min_confidence = a.min_confidence;
  o.refine.paper.binding_cents = a.binding_cents;
  o.refine.ik.max_residual_mm = a.max_residual_mm;
  o.refine.ik.lift_max_distance_mm = a.lift_max_mm;
  o.refine.ik.max_hand_shift_mm = a.max_hand_shift_mm;
  if (a.joints == "pip_dip") o.refine.ik.joints = hand::FingerIkJoints::kPipDip;
  if (a.joints == "all") o.refine.ik.joints = hand::FingerIkJoints::kAll;
  if (a.reference_weight >= 0) o.refine.ik.reference_weight_mm_per_rad = a.reference_weight;
  if (a.temporal_weight >= 0) o.refine.ik.temporal_weight_mm_per_rad = a.temporal_weight;
  if (a.exact_reach) o.refine.ik.exact_reach = true;
  if (a.no_audio_onsets) o.refine.decode.audio_onsets = false;
  if (a.normal_weight >= 0) o.refine.decode.normal_weight = a.normal_weight;
  if (a.lateral_weight >= 0) o.refine.decode.lateral_weight = a.lateral_weight;
  if (a.hand_lateral_weight >= 0) o.refine.decode.hand_lateral_weight = a.hand_lateral_weight;
  if (a.shift_cost >= 0) o.refine.decode.shift_cost_per_semitone = a.shift_cost;
  if (a.neighbour_shift_frames >= 0) o.refine.ik.neighbour_shift_frames = a.neighbour_shift_frames;
  if (a.straddle_s >= 0) o.refine.decode.boundaries.straddle_s = a.straddle_s;
  if (a.onset_tolerance_s >= 0) o.refine.decode.boundaries.onset_tolerance_s = a.onset_tolerance_s;
  const Status valid = o.Validate();
  if (!valid.ok()) return PrintError(valid.message());
  auto summary = pipeline::RunRefineStage(o);
  if (!summary.ok()) return PrintError(summary.status().message());
  std::printf("%s\nwrote %s/%s/\n",
              FormatRefineSummary(*summary).c_str(),
              a.result.c_str(),
              refine::RefineModeName(*mode));
  return 0;
}

std::function<int()> SetupRefine(CLI::App& app) {
  auto* sub = app.add_subcommand(
      "refine", "Re-run only the audio-guided refinement on a result folder of `arco run`");
  auto a = std::make_shared<RefineArgs>();
  sub->add_option("result", a->result, "Result folder written by `arco run`")->required();
  sub->add_option("--mode",
                  a->mode,
                  "paper: the published method (wrist-nearest candidate, nearest fingertip, "
                  "+-30 cents binding, PIP/DIP IK); arco: Viterbi decoding and bounded "
                  "MCP/PIP/DIP IK with a lift test; vision: the fitted hand as is")
      ->check(CLI::IsMember({"paper", "arco", "vision"}))
      ->capture_default_str();
  sub->add_option(
         "--threads", a->threads, "Worker threads (0 = all cores; results do not depend on it)")
      ->capture_default_str();
  sub->add_option("--min-confidence",
                  a->min_confidence,
                  "Pitch confidence below which a frame gets no contact (0-1)")
      ->capture_default_str();
  sub->add_option("--binding-cents",
                  a->binding_cents,
                  "paper: keep the finger binding while the pitch stays within this many cents")
      ->capture_default_str();
  sub->add_option("--max-residual-mm",
                  a->max_residual_mm,
                  "arco: reject a contact the bounded IK cannot bring the tip within this "
                  "distance of (mm)")
      ->capture_default_str();
  sub->add_option("--max-hand-shift-mm",
                  a->max_hand_shift_mm,
                  "arco: when the finger alone cannot reach, move the whole hand up to this far "
                  "(mm); beyond it the contact is rejected")
      ->capture_default_str();
  sub->add_option("--lift-max-mm",
                  a->lift_max_mm,
                  "arco: reject contacts farther than this from the fitted fingertip (mm; 0 = "
                  "the finger's tip-to-PIP length)")
      ->capture_default_str();
  sub->add_option("--joints", a->joints, "arco: free joints of the playing finger")
      ->check(CLI::IsMember({"all", "mcp_flex_pip_dip", "pip_dip"}))
      ->capture_default_str();
  sub->add_option("--reference-weight",
                  a->reference_weight,
                  "arco: IK prior toward the fitted angles (mm per rad; default 1)");
  sub->add_option("--temporal-weight",
                  a->temporal_weight,
                  "arco: IK prior toward the previous frame's solution (mm per rad; default 4)");
  sub->add_flag("--exact-reach",
                a->exact_reach,
                "arco: the hand IK's exact reach instead of one regularised (least change) solve");
  sub->add_flag("--no-audio-onsets",
                a->no_audio_onsets,
                "arco: assign the frames at note changes by their own pitch only, not by the "
                "onsets of the audio's notes (notes.csv)");
  sub->add_option("--onset-tolerance-s",
                  a->onset_tolerance_s,
                  "arco: a frame this long before an audio onset belongs to the new note (s; "
                  "default 0.017)");
  sub->add_option("--neighbour-shift-frames",
                  a->neighbour_shift_frames,
                  "arco: a frame the lift test rejected starts from the hand shift of its "
                  "accepted neighbours of the same note within this many frames (0: off; "
                  "default 2)");
  sub->add_option("--straddle-s",
                  a->straddle_s,
                  "arco: a note's frames this soon after its audio onset whose pitch is off "
                  "the note's take the note's pitch (s; default 0.034, 0: off)");
  sub->add_option("--normal-weight",
                  a->normal_weight,
                  "arco decoding: weight of the tip-to-contact distance along the string "
                  "plane's normal");
  sub->add_option("--lateral-weight",
                  a->lateral_weight,
                  "arco decoding: weight of the tip-to-contact distance across the string");
  sub->add_option("--hand-lateral-weight",
                  a->hand_lateral_weight,
                  "arco decoding: weight of the hand's median fingertip offset across the "
                  "strings");
  sub->add_option("--shift-cost",
                  a->shift_cost,
                  "arco decoding: cost per semitone of hand-position change between notes");
  return [a]() { return RunRefine(*a); };
}

}  // namespace
ARCO_REGISTER_COMMAND(refine, 55, SetupRefine);
}  // namespace arco::cli
