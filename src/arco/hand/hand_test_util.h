// Test helpers: seeded random joint-limited hand poses.
#pragma once

#include <Eigen/Geometry>
#include <random>

#include "arco/hand/hand_model.h"

namespace arco::hand::testing {

// Angles uniform inside the limits (shrunk by `margin` of each range), a random
// wrist rotation and a wrist position near `center_mm`.
inline HandPose RandomPose(const HandModel& model,
                           std::mt19937& rng,
                           double margin = 0.0,
                           const Eigen::Vector3d& center_mm = Eigen::Vector3d::Zero()) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n(0.0, 1.0);
  HandPose pose;
  for (int d = 0; d < kNumJointDofs; ++d) {
    const double lo = model.min_rad(d), hi = model.max_rad(d), w = hi - lo;
    pose.angles_rad[d] = lo + margin * w + u(rng) * (1 - 2 * margin) * w;
  }
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  pose.world_from_wrist.rotation = q.normalized().toRotationMatrix();
  pose.world_from_wrist.translation = center_mm + Eigen::Vector3d(n(rng), n(rng), n(rng)) * 30.0;
  return pose;
}

}  // namespace arco::hand::testing
