// Library messages name the options-struct fields they check ("start_s must be
// ..."), so they read right from any caller (CLI, Python, a workflow). Where the CLI
// prints one, it names the flag that sets the field instead ("--start-s must be ...").
#pragma once

#include <cctype>
#include <string>
#include <string_view>

namespace arco::cli {

struct FieldFlag {
  std::string_view field, flag;
};

// Pitch (PitchTrackerOptions, as set by `arco pitch`).
inline constexpr FieldFlag kPitchFlags[] = {{"fps", "--fps"},
                                            {"start_s", "--start-s"},
                                            {"a4_hz", "--a4"},
                                            {"min_f0_hz", "--fmin"},
                                            {"max_f0_hz", "--fmax"}};
// Sync (SyncOptions, as set by `arco sync`).
inline constexpr FieldFlag kSyncFlags[] = {{"video_fps", "--fps"},
                                           {"search_s", "--search-s"},
                                           {"audio_near_s", "--audio-near-s"},
                                           {"video_near_s", "--video-near-s"},
                                           {"max_seconds", "--max-s"}};
// Refinement (RefineOptions, as set by `arco refine` and `arco run`).
inline constexpr FieldFlag kRefineFlags[] = {
    {"num_threads", "--threads"},
    {"min_confidence", "--min-confidence"},
    {"binding_cents", "--binding-cents"},
    {"max_residual_mm", "--max-residual-mm"},
    {"max_hand_shift_mm", "--max-hand-shift-mm"},
    {"lift_max_distance_mm", "--lift-max-mm"},
    {"reference_weight_mm_per_rad", "--reference-weight"},
    {"temporal_weight_mm_per_rad", "--temporal-weight"},
    {"onset_tolerance_s", "--onset-tolerance-s"},
    {"neighbour_shift_frames", "--neighbour-shift-frames"},
    {"straddle_s", "--straddle-s"},
    {"normal_weight", "--normal-weight"},
    {"lateral_weight", "--lateral-weight"},
    {"hand_lateral_weight", "--hand-lateral-weight"},
    {"shift_cost_per_semitone", "--shift-cost"},
    {"one_view_shift_cost_factor", "--one-view-shift-cost-factor"},
    {"one_view_lateral_weight", "--one-view-lateral-weight"},
    {"one_view_above_margin_mm", "--one-view-above-margin-mm"},
    {"frame_sigma_mm", "--one-view-frame-sigma-mm"},
    {"one_view_smoothing_s", "--one-view-smoothing-s"},
    {"one_view_same_note_weight", "--one-view-same-note-weight"}};
// Evaluation (EvaluateRequest, as set by `arco eval`).
inline constexpr FieldFlag kEvalFlags[] = {{"truth_frames", "--truth-frame"},
                                           {"pck_thresholds_mm", "--pck-mm"},
                                           {"joint_limit_tolerance_deg", "--limit-tolerance-deg"}};
// Export (exporter::ExportOptions, as set by `arco export`).
inline constexpr FieldFlag kExportFlags[] = {
    {"result_dir", "RESULT_DIR"}, {"format", "--format"}, {"method", "--method"}};
// Synthesis (CaptureWriteOptions, as set by `arco synth`).
inline constexpr FieldFlag kSynthFlags[] = {{"instrument", "--instrument"},
                                            {"piece", "--piece"},
                                            {"overwrite", "--overwrite"},
                                            {"max_duration_s", "--duration-s"},
                                            {"noise_px", "--noise-px"},
                                            {"outlier_rate", "--outlier-rate"},
                                            {"occlusion_rate", "--occlusion-rate"},
                                            {"finger_bias_mm", "--finger-bias-mm"},
                                            {"jitter_mm", "--jitter-mm"},
                                            {"finger_offset_mm", "--finger-offset-mm"},
                                            {"hand_back_max_deg", "--hand-back-deg"},
                                            {"finger_confusion_rate", "--finger-confusion-rate"},
                                            {"mm_per_unit", "--mm-per-unit"}};

// `text` with every whole-word field name of `names` replaced by its flag. A name quoted
// or qualified (`"fps"`, `audio.offset_s`) is a file's field (mocap/capture.h writes
// them so), and one between slashes part of a path: never rewritten (a message about
// capture.json must not name a flag). Nor is a name right after a number and a space: a
// unit ("right.mp4: 60 fps, but left.mp4 has 30 fps" is about the videos, not --fps).
template <size_t N>
std::string WithFlagNames(std::string text, const FieldFlag (&names)[N]) {
  auto word_char = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  for (const FieldFlag& name : names) {
    for (size_t at = text.find(name.field); at != std::string::npos;
         at = text.find(name.field, at)) {
      const size_t end = at + name.field.size();
      const bool whole = (at == 0 || !word_char(text[at - 1])) &&
                         (end == text.size() || (!word_char(text[end]) && text[end] != '/')) &&
                         (at == 0 || (text[at - 1] != '-' && text[at - 1] != '"' &&
                                      text[at - 1] != '.' && text[at - 1] != '/')) &&
                         !(at >= 2 && text[at - 1] == ' ' &&
                           std::isdigit(static_cast<unsigned char>(text[at - 2])));
      if (!whole) {
        at = end;
        continue;
      }
      text.replace(at, name.field.size(), name.flag);
      at += name.flag.size();
    }
  }
  return text;
}

}  // namespace arco::cli
