#include "arco/hand/one_view_depth.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "arco/util/number_range.h"
#include "arco/util/stats.h"

namespace arco::hand {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

Status OneViewDepthOptions::Validate() const {
  return CheckInRange("window_frames", window_frames, Closed(0, 300));
}

StatusOr<OneViewDepthSummary> MoveHandsAlongRays(const Eigen::Vector3d& centre,
                                                 const std::vector<double>& shift_mm,
                                                 const OneViewDepthOptions& options,
                                                 std::vector<std::optional<HandPose>>* hands) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  if (shift_mm.size() != hands->size())
    return Status::Error("MoveHandsAlongRays: " + std::to_string(shift_mm.size()) + " shifts for " +
                         std::to_string(hands->size()) + " frames");
  const int64_t frames = static_cast<int64_t>(hands->size());
  OneViewDepthSummary summary;
  std::vector<double> applied;
  // Each frame's wanted wrist distance from the camera (its own plus its shift); the
  // median of these over the frames around is where the wrist goes. Smoothing the wanted
  // distance, not the shift, also removes the fit's own depth jitter (a few pixels of a
  // hand's size in the image are centimetres of depth), which a smoothed shift keeps: on
  // the real take, one camera, arco's left hand within 15 mm in the instrument's frame on
  // 0.130-0.318 -> 0.176-0.345 of frames over five error models (docs/accuracy.md).
  std::vector<double> wanted(hands->size(), kNaN), range_of(hands->size(), kNaN);
  for (size_t f = 0; f < hands->size(); ++f) {
    if (!(*hands)[f]) continue;
    range_of[f] = ((*hands)[f]->world_from_wrist.translation - centre).norm();
    wanted[f] = range_of[f] + shift_mm[f];
  }
  for (int64_t f = 0; f < frames; ++f) {
    std::optional<HandPose>& pose = (*hands)[static_cast<size_t>(f)];
    if (!pose) continue;
    std::vector<double> around;
    for (int64_t g = std::max<int64_t>(0, f - options.window_frames);
         g <= std::min(frames - 1, f + options.window_frames);
         ++g) {
      if (std::isfinite(wanted[static_cast<size_t>(g)]))
        around.push_back(wanted[static_cast<size_t>(g)]);
    }
    if (around.empty()) continue;
    const double s = UpperMedian(around) - range_of[static_cast<size_t>(f)];
    Eigen::Vector3d& wrist = pose->world_from_wrist.translation;
    const double range = (wrist - centre).norm();
    if (!(range > 0) || !(range + s > 0)) continue;
    wrist += s / range * (wrist - centre);
    applied.push_back(s);
    ++summary.frames_moved;
  }
  summary.median_shift_mm = UpperMedian(applied);
  return summary;
}

StatusOr<OneViewDepthSummary> AlignHandDepth(const HandModel& model,
                                             const Eigen::Vector3d& centre,
                                             const std::vector<double>& tip_distance_mm,
                                             const OneViewDepthOptions& options,
                                             std::vector<std::optional<HandPose>>* hands) {
  if (tip_distance_mm.size() != hands->size())
    return Status::Error("AlignHandDepth: " + std::to_string(tip_distance_mm.size()) +
                         " distances for " + std::to_string(hands->size()) + " frames");
  // Each frame's shift: the wanted distance minus the fitted fingertips' median distance.
  std::vector<double> shift(hands->size(), kNaN);
  for (size_t f = 0; f < hands->size(); ++f) {
    const std::optional<HandPose>& pose = (*hands)[f];
    if (!pose || !std::isfinite(tip_distance_mm[f])) continue;
    const HandPointsMm points = ForwardKinematics(model, *pose);
    std::vector<double> tips;
    for (Finger finger : {Finger::kIndex, Finger::kMiddle, Finger::kRing, Finger::kLittle})
      tips.push_back((points[TipKeypoint(finger)] - centre).norm());
    shift[f] = tip_distance_mm[f] - UpperMedian(tips);
  }
  return MoveHandsAlongRays(centre, shift, options, hands);
}

}  // namespace arco::hand
