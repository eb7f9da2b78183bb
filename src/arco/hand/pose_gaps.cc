#include "arco/hand/pose_gaps.h"

#include <Eigen/Geometry>

namespace arco::hand {

Status PoseGapOptions::Validate() const {
  if (!(max_gap_frames >= 0 && max_gap_frames <= 1000))
    return Status::Error("max_gap_frames must be in [0, 1000]");
  return Status::Ok();
}

StatusOr<int> FillHandPoseGaps(const PoseGapOptions& options,
                               std::vector<std::optional<HandPose>>* hands) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  std::vector<std::optional<HandPose>>& h = *hands;
  const int n = static_cast<int>(h.size());
  int filled = 0;
  int previous = -1;  // the last fitted frame before the current gap
  for (int f = 0; f < n; ++f) {
    if (!h[static_cast<size_t>(f)]) continue;
    const int gap = previous < 0 ? 0 : f - previous - 1;
    if (gap > 0 && gap <= options.max_gap_frames) {
      const HandPose& a = *h[static_cast<size_t>(previous)];
      const HandPose& b = *h[static_cast<size_t>(f)];
      const Eigen::Quaterniond qa(a.world_from_wrist.rotation), qb(b.world_from_wrist.rotation);
      for (int g = previous + 1; g < f; ++g) {
        const double t = static_cast<double>(g - previous) / static_cast<double>(f - previous);
        HandPose p;
        for (size_t d = 0; d < p.angles_rad.size(); ++d)
          p.angles_rad[d] = (1 - t) * a.angles_rad[d] + t * b.angles_rad[d];
        p.world_from_wrist.rotation = qa.slerp(t, qb).normalized().toRotationMatrix();
        p.world_from_wrist.translation =
            (1 - t) * a.world_from_wrist.translation + t * b.world_from_wrist.translation;
        h[static_cast<size_t>(g)] = p;
        ++filled;
      }
    }
    previous = f;
  }
  return filled;
}

}  // namespace arco::hand
