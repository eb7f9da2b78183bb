// The SPD-compatible points of a refined method (docs/formats.md, "Method folders"):
// RESULT_DIR/<method>/points3d.npy is (F, 155, 3) cello / (F, 153, 3) violin, float64,
// millimetres, NaN = missing, in the layout spd_cello_contact / spd_violin_contact
// (registry/keypoint_layout.h; DOMAIN.md section 3). The folder itself is written by the
// result folder's owner (pipeline/result_folder.h).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "arco/hand/hand_model.h"
#include "arco/instrument/instrument_model.h"
#include "arco/instrument/strings.h"
#include "arco/refine/contact_annotation.h"
#include "arco/util/npy.h"

namespace arco::refine {

// The SPD-compatible layout name of an instrument ("spd_cello_contact", ...).
std::string SpdContactLayoutName(const InstrumentModel& model);

// What every method shares when its points3d.npy is assembled.
struct SpdSources {
  std::shared_ptr<const InstrumentModel> instrument;
  hand::HandModel hand_model = hand::HandModel::Default(hand::HandSide::kLeft);
  // (F, 133 + instrument keypoints, 3) in mm: body, right hand, instrument and bow (the
  // left hand's rows are replaced from each method's hands where it has one).
  NpyArray<double> base_points_mm;
  // Per frame, index = string - 1, world mm; empty = none (string points NaN).
  std::vector<std::vector<StringSegment>> strings_in_world_mm;
};

// (F, 133 + instrument keypoints + 13, 3): the base points, the left hand (91-111) by
// forward kinematics of `hands`, then the contact stage (DOMAIN.md section 3): the strings
// as (nut, bridge) pairs from the lowest string to the highest, the contact point, and the
// playing finger's MCP, PIP, DIP and tip on pressed frames (NaN otherwise). `contacts` may
// be null (vision). Throws std::invalid_argument when sizes disagree.
NpyArray<double> BuildSpdPoints(const SpdSources& sources,
                                const std::vector<std::optional<hand::HandPose>>& hands,
                                const std::vector<FrameContact>* contacts);

}  // namespace arco::refine
