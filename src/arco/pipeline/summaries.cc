#include "arco/pipeline/summaries.h"

namespace arco::pipeline {

Json ToJson(const InstrumentStageSummary& s) {
  return {{"frames", s.frames},
          {"frames_with_pose", s.frames_with_pose},
          {"frames_high_residual", s.frames_high_residual},
          {"median_rms_residual_mm", JsonFromDouble(s.median_rms_residual_mm)},
          {"front_agreement", JsonFromDouble(s.front_agreement)},
          {"string_order_ambiguous", s.string_order_ambiguous},
          {"labels_agree", s.labels_agree},
          {"smoothing_sigma_frames", JsonFromDouble(s.smoothing_sigma_frames)}};
}

Json ToJson(const HandStageSummary& s) {
  return {{"frames", s.frames},
          {"frames_fitted", s.frames_fitted},
          {"frames_interpolated", s.frames_interpolated},
          {"median_rms_residual_px", JsonFromDouble(s.median_rms_residual_px)},
          {"median_residual_px", JsonFromDouble(s.median_residual_px)},
          {"bone_lengths_from_data", s.bone_lengths_from_data},
          {"palm_from_data", s.palm_from_data},
          {"palm_frames", s.palm_frames},
          {"palm_max_shift_mm", s.palm_max_shift_mm},
          {"palm_bases_kept", s.palm_bases_kept}};
}

Json ToJson(const PitchStageSummary& s) {
  return {{"duration_s", s.duration_s}, {"voiced_fraction", s.voiced_fraction}, {"notes", s.notes}};
}

}  // namespace arco::pipeline
