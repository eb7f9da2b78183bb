// The 26 numbers of a hand pose as one row, the format of every hand-pose array arco
// writes (the result folder's hand_params.npy, the synthetic truth's *_hand_pose.npy):
// the wrist rotation as an angle-axis (3, rad), the wrist position (3, mm), the 20 joint
// angles (rad, hand_model.h). A row with any NaN is no hand.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "arco/hand/hand_model.h"
#include "arco/util/npy.h"
#include "arco/util/status.h"

namespace arco::hand {

inline constexpr int kHandParamsColumns = 6 + kNumJointDofs;  // angle-axis, wrist, joints

// (F, 26) rows of per-frame hands; a frame without a hand is a row of NaN.
NpyArray<double> HandParams(const std::vector<std::optional<HandPose>>& hands);
// The inverse: rows with any NaN are no hand. Errors on a shape other than (F, 26),
// naming `source`.
StatusOr<std::vector<std::optional<HandPose>>> HandsFromParams(const NpyArray<double>& params,
                                                               const std::string& source);

}  // namespace arco::hand
