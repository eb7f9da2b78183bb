#include "arco/hand/hand_params.h"

#include <cmath>
#include <limits>

namespace arco::hand {

NpyArray<double> HandParams(const std::vector<std::optional<HandPose>>& hands) {
  NpyArray<double> out;
  const int64_t n = static_cast<int64_t>(hands.size());
  out.shape = {n, kHandParamsColumns};
  out.data.assign(static_cast<size_t>(n * kHandParamsColumns),
                  std::numeric_limits<double>::quiet_NaN());
  for (int64_t f = 0; f < n; ++f) {
    const auto& h = hands[static_cast<size_t>(f)];
    if (!h) continue;
    const Eigen::Vector3d aa = h->WristAngleAxis();
    for (int c = 0; c < 3; ++c) {
      out.at(f, c) = aa[c];
      out.at(f, 3 + c) = h->world_from_wrist.translation[c];
    }
    for (int d = 0; d < kNumJointDofs; ++d)
      out.at(f, 6 + d) = h->angles_rad[static_cast<size_t>(d)];
  }
  return out;
}

StatusOr<std::vector<std::optional<HandPose>>> HandsFromParams(const NpyArray<double>& params,
                                                               const std::string& source) {
  if (params.shape.size() != 2 || params.shape[1] != kHandParamsColumns) {
    return Status::Error(source + ": hand parameters must have shape (frames, 26)");
  }
  std::vector<std::optional<HandPose>> out(static_cast<size_t>(params.shape[0]));
  for (int64_t f = 0; f < params.shape[0]; ++f) {
    bool finite = true;
    for (int i = 0; i < kHandParamsColumns; ++i) finite = finite && std::isfinite(params.at(f, i));
    if (!finite) continue;
    HandPose pose;
    pose.SetWristAngleAxis(Eigen::Vector3d(params.at(f, 0), params.at(f, 1), params.at(f, 2)));
    pose.world_from_wrist.translation =
        Eigen::Vector3d(params.at(f, 3), params.at(f, 4), params.at(f, 5));
    for (int d = 0; d < kNumJointDofs; ++d)
      pose.angles_rad[static_cast<size_t>(d)] = params.at(f, 6 + d);
    out[static_cast<size_t>(f)] = pose;
  }
  return out;
}

}  // namespace arco::hand
