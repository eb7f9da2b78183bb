// Internal to the refinement: what both decoders (paper_decode.h, arco_decode.h) read.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "arco/hand/kinematics.h"
#include "arco/refine/contact_annotation.h"
#include "arco/refine/pitch_model.h"
#include "arco/refine/refine.h"

namespace arco::refine {

struct DecodeContext {
  const RefineInput* input = nullptr;
  const PitchAnalysis* analysis = nullptr;
  // Per frame: the vision hand's keypoints (world mm), when there is a hand.
  std::vector<std::optional<hand::HandPointsMm>> vision_points;
  // Per frame: the strings are present and finite.
  std::vector<uint8_t> has_strings;

  int num_frames() const { return static_cast<int>(has_strings.size()); }
  const std::vector<StringSegment>& strings(int f) const {
    return input->strings_in_world_mm[static_cast<size_t>(f)];
  }
};

// Builds the context (forward kinematics of every vision hand, in parallel).
DecodeContext MakeDecodeContext(const RefineInput& input,
                                const PitchAnalysis& analysis,
                                int num_threads);

// The annotation the audio alone gives a frame: rest, uncertain with its reason, or (for a
// usable note frame) kUncertain with reason kNone, for a decoder to fill in. Sets f0,
// confidence and note.
FrameContact AudioOnlyContact(const DecodeContext& context, int frame);

// Fills the contact fields of `out` from a candidate (state kPressed).
void SetPressed(const Candidate& candidate, int finger, FrameContact* out);

// A string's unit direction (bridge -> nut) and the unit normal of the string plane
// (sign arbitrary) on one frame's strings.
struct StringFrame {
  Eigen::Vector3d along = Eigen::Vector3d::UnitX();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};
StringFrame StringFrameOf(const std::vector<StringSegment>& strings, int string);

}  // namespace arco::refine
