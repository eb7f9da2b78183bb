// Test/benchmark helper: a synthetic ring of cameras looking at a point, and
// projection of a hand into it with pixel noise and outliers (generated truth).
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "arco/camera/camera.h"
#include "arco/hand/fit.h"
#include "arco/testing/look_at.h"

namespace arco::hand::testing {

// `n` cameras on two rings (radius_mm, heights +-0.3 radius) looking at `target`.
inline std::vector<Camera> MakeRingRig(int n, double radius_mm, const Eigen::Vector3d& target) {
  std::vector<Camera> cameras(n);
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    const double h = (i % 2 == 0 ? 0.3 : -0.3) * radius_mm;
    const Eigen::Vector3d center =
        target + Eigen::Vector3d(radius_mm * std::cos(a), h, radius_mm * std::sin(a));
    Camera& c = cameras[i];
    c.name = "cam" + std::to_string(i);
    c.width = 2300;
    c.height = 2656;
    c.fx = c.fy = 3200;  // SPD-like: a hand of ~180 mm spans ~230 px at 2.5 m
    c.cx = 1149.5;
    c.cy = 1327.5;
    c.distortion.k1 = -0.08;
    c.cam_from_world.rotation =
        arco::testing::CamFromWorldLookingAt(center, target, Eigen::Vector3d::UnitY());
    c.cam_from_world.translation = -c.cam_from_world.rotation * center;
  }
  return cameras;
}

// Projects `points` into every camera with Gaussian noise (noise_px), a share
// of outlier keypoints (moved by 40-200 px) and scores in [0.5, 1].
inline std::vector<HandKeypoints2d> ProjectHand(const std::vector<Camera>& cameras,
                                                const HandPointsMm& points,
                                                double noise_px,
                                                double outlier_fraction,
                                                std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<HandKeypoints2d> views(cameras.size());
  for (size_t v = 0; v < cameras.size(); ++v) {
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      const auto px = cameras[v].Project(points[k]);
      views[v].pixels[k] = px ? *px : Eigen::Vector2d::Constant(std::nan(""));
      views[v].scores[k] = px ? 0.5 + 0.5 * u(rng) : 0.0;
      views[v].pixels[k] += noise_px * Eigen::Vector2d(n(rng), n(rng));
      if (u(rng) < outlier_fraction) {
        const double angle = 2 * M_PI * u(rng), r = 40 + 160 * u(rng);
        views[v].pixels[k] += r * Eigen::Vector2d(std::cos(angle), std::sin(angle));
      }
    }
  }
  return views;
}

}  // namespace arco::hand::testing
