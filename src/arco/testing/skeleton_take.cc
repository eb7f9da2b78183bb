#include "arco/testing/skeleton_take.h"

#include <Eigen/Geometry>
#include <limits>
#include <random>

#include "arco/body/skeleton.h"

namespace arco::testing {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Take MakeTake(int frames, double noise_mm, uint32_t seed) {
  using body::JointGroup;
  using body::SkeletonJoint;
  using body::WholeBodySkeleton;
  const std::vector<SkeletonJoint>& s = WholeBodySkeleton();
  const int n = static_cast<int>(s.size());
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Eigen::Vector3d> offset(n, Eigen::Vector3d::Zero());
  for (int i = 1; i < n; ++i) {
    const double length = s[i].group == JointGroup::kBody ? 80 + 300 * u(rng) : 20 + 30 * u(rng);
    offset[i] = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized() * length;
  }
  for (int i = 0; i < n; ++i) {  // midpoint joints lie between their two keypoints
    if (s[i].keypoint.empty()) {
      int a = -1, b = -1;
      for (int c : s[i].children) {
        if (s[c].keypoint == s[i].mid_a) a = c;
        if (s[c].keypoint == s[i].mid_b) b = c;
      }
      offset[b] = -offset[a];
    }
  }
  Take t;
  std::vector<int> key(n, -1);
  for (int i = 0; i < n; ++i) {
    if (s[i].keypoint.empty()) continue;
    key[i] = static_cast<int>(t.names.size());
    t.names.push_back(s[i].keypoint);
  }
  const int p = static_cast<int>(t.names.size());
  t.truth.shape = {frames, p, 3};
  t.truth.data.assign(static_cast<size_t>(frames * p * 3), kNaN);
  std::vector<Eigen::Vector3d> axis(n), rate(n);
  for (int i = 0; i < n; ++i) {
    axis[i] = Eigen::Vector3d(g(rng), g(rng), g(rng));
    rate[i] = 0.05 * Eigen::Vector3d(g(rng), g(rng), g(rng));
  }
  for (int f = 0; f < frames; ++f) {
    std::vector<Eigen::Vector3d> x(n);
    std::vector<Eigen::Matrix3d> r(n);
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d aa = axis[i] + f * rate[i];
      r[i] = Eigen::AngleAxisd(aa.norm(), aa.normalized()).toRotationMatrix();
      x[i] = s[i].parent < 0 ? Eigen::Vector3d(100 + 2.0 * f, -50 + f, 900)
                             : Eigen::Vector3d(x[s[i].parent] + r[s[i].parent] * offset[i]);
      if (key[i] >= 0) {
        for (int a = 0; a < 3; ++a) t.truth.at(f, key[i], a) = x[i][a];
      }
    }
  }
  t.noisy = t.truth;
  for (int f = 0; f < frames; ++f) {
    for (int k = 0; k < p; ++k) {
      const double draw = u(rng);
      for (int a = 0; a < 3; ++a) {
        double& v = t.noisy.at(f, k, a);
        if (draw < 0.05) {
          v = kNaN;  // missing
        } else {
          v += noise_mm * g(rng) + (draw > 0.99 ? 60.0 : 0.0);  // 1 % gross outliers
        }
      }
    }
  }
  return t;
}

}  // namespace arco::testing
