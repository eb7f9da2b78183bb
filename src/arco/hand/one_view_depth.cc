#include "arco/hand/one_view_depth.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "arco/util/number_range.h"

namespace arco::hand {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double Median(std::vector<double> v) {
  if (v.empty()) return kNaN;
  const auto mid = v.begin() + static_cast<long>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

Status OneViewDepthOptions::Validate() const {
  return CheckInRange("window_frames", window_frames, Closed(0, 300));
}

StatusOr<OneViewDepthSummary> AlignHandDepth(const HandModel& model,
                                             const Camera& camera,
                                             const std::vector<double>& tip_depth_mm,
                                             const OneViewDepthOptions& options,
                                             std::vector<std::optional<HandPose>>* hands) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  if (tip_depth_mm.size() != hands->size())
    return Status::Error("AlignHandDepth: " + std::to_string(tip_depth_mm.size()) + " depths for " +
                         std::to_string(hands->size()) + " frames");
  const int64_t frames = static_cast<int64_t>(hands->size());
  // Each frame's shift: the wanted depth minus the fitted fingertips' median depth.
  std::vector<double> shift(static_cast<size_t>(frames), kNaN);
  for (int64_t f = 0; f < frames; ++f) {
    const std::optional<HandPose>& pose = (*hands)[static_cast<size_t>(f)];
    if (!pose || !std::isfinite(tip_depth_mm[static_cast<size_t>(f)])) continue;
    const HandPointsMm points = ForwardKinematics(model, *pose);
    std::vector<double> tips;
    for (Finger finger : {Finger::kIndex, Finger::kMiddle, Finger::kRing, Finger::kLittle})
      tips.push_back(camera.PointInCamera(points[TipKeypoint(finger)]).z());
    shift[static_cast<size_t>(f)] = tip_depth_mm[static_cast<size_t>(f)] - Median(tips);
  }
  OneViewDepthSummary summary;
  std::vector<double> applied;
  const Eigen::Vector3d centre = camera.CenterInWorld();
  for (int64_t f = 0; f < frames; ++f) {
    std::optional<HandPose>& pose = (*hands)[static_cast<size_t>(f)];
    if (!pose) continue;
    std::vector<double> around;
    for (int64_t g = std::max<int64_t>(0, f - options.window_frames);
         g <= std::min(frames - 1, f + options.window_frames);
         ++g) {
      if (std::isfinite(shift[static_cast<size_t>(g)]))
        around.push_back(shift[static_cast<size_t>(g)]);
    }
    if (around.empty()) continue;
    const double s = Median(around);
    // Along the wrist's ray, by the vector whose depth component is s: every keypoint's
    // depth (the fingertips' too) changes by exactly s, and the wrist's image stays.
    const Eigen::Vector3d& wrist = pose->world_from_wrist.translation;
    const double d = camera.PointInCamera(wrist).z();
    if (!(d > 0) || !(d + s > 0)) continue;
    pose->world_from_wrist.translation = wrist + s / d * (wrist - centre);
    applied.push_back(s);
    ++summary.frames_moved;
  }
  summary.median_shift_mm = Median(applied);
  return summary;
}

}  // namespace arco::hand
