#include "arco/testing/synthetic_views.h"

#include <cmath>
#include <limits>
#include <string>

#include "arco/geometry/robust.h"
#include "arco/testing/look_at.h"

namespace arco::testing {
namespace {

double Uniform01(SplitMix64* rng) { return (rng->Next() >> 11) * (1.0 / 9007199254740992.0); }

// Box-Muller; deterministic given the generator.
double Gaussian(SplitMix64* rng) {
  const double u1 = std::max(Uniform01(rng), 1e-300);
  const double u2 = Uniform01(rng);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

}  // namespace

Rig MakeSyntheticRig(const SyntheticRigOptions& options) {
  SplitMix64 rng(options.seed);
  Rig rig;
  rig.units = "m";
  const Eigen::Vector3d target(0, 0, 1.0);
  for (int i = 0; i < options.num_cameras; ++i) {
    const double a = 2 * M_PI * i / options.num_cameras + 0.05 * (Uniform01(&rng) - 0.5);
    const double h = 1.2 + ((i % 2) ? 0.5 : -0.5) * options.height_spread_m;
    const Eigen::Vector3d center(options.radius_m * std::cos(a), options.radius_m * std::sin(a), h);
    const Eigen::Vector3d aim =
        target + Eigen::Vector3d(0.1 * (Uniform01(&rng) - 0.5), 0.1 * (Uniform01(&rng) - 0.5), 0);
    Camera cam;
    cam.name = "cam" + std::to_string(i);
    cam.serial = std::to_string(30000000 + i);
    cam.width = 2300;
    cam.height = 2656;
    cam.fx = cam.fy = 2260.0;
    cam.cx = 1149.5 - 5.4;
    cam.cy = 1327.5 - 8.5;
    if (options.distortion) cam.distortion = {-0.081, 0.066, 0.0195, -0.00035, 0.00062};
    // Portrait cameras (like SPD's rotated images): image y points down the world z axis.
    cam.cam_from_world.rotation = CamFromWorldLookingAt(center, aim);
    cam.cam_from_world.translation = -cam.cam_from_world.rotation * center;
    rig.cameras.push_back(cam);
  }
  return rig;
}

NpyArray<double> MakeSyntheticPoints(int64_t frames, int64_t points, uint64_t seed) {
  SplitMix64 rng(seed);
  NpyArray<double> out;
  out.shape = {frames, points, 3};
  out.data.resize(static_cast<size_t>(frames * points * 3));
  for (int64_t p = 0; p < points; ++p) {
    const Eigen::Vector3d base(
        0.8 * (Uniform01(&rng) - 0.5), 0.8 * (Uniform01(&rng) - 0.5), 0.3 + 1.3 * Uniform01(&rng));
    const Eigen::Vector3d amp =
        0.05 * Eigen::Vector3d(Uniform01(&rng), Uniform01(&rng), Uniform01(&rng));
    const double freq_hz = 0.2 + 1.5 * Uniform01(&rng), phase = 2 * M_PI * Uniform01(&rng);
    for (int64_t f = 0; f < frames; ++f) {
      const double s = std::sin(2 * M_PI * freq_hz * f / 30.0 + phase);
      for (int k = 0; k < 3; ++k) out.at(f, p, k) = base[k] + amp[k] * s;
    }
  }
  return out;
}

NpyArray<double> MakeSyntheticDetections(const Rig& rig,
                                         const NpyArray<double>& points3d,
                                         const SyntheticDetectionOptions& options) {
  SplitMix64 rng(options.seed);
  const int64_t frames = points3d.shape[0], points = points3d.shape[1];
  const int64_t views = static_cast<int64_t>(rig.cameras.size());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  NpyArray<double> out;
  out.shape = {frames, views, points, 3};
  out.data.assign(static_cast<size_t>(frames * views * points * 3), nan);
  for (int64_t f = 0; f < frames; ++f) {
    for (int64_t v = 0; v < views; ++v) {
      for (int64_t p = 0; p < points; ++p) {
        // Draw every random number in a fixed order so options do not shift streams.
        const double n0 = Gaussian(&rng), n1 = Gaussian(&rng);
        const double u_missing = Uniform01(&rng), u_outlier = Uniform01(&rng);
        const double u_angle = Uniform01(&rng), u_dist = Uniform01(&rng);
        const double u_score = Uniform01(&rng);
        if (u_missing < options.missing_fraction) continue;
        const Eigen::Vector3d x(points3d.at(f, p, 0), points3d.at(f, p, 1), points3d.at(f, p, 2));
        const auto pixel = rig.cameras[v].Project(x);
        if (!pixel) continue;
        Eigen::Vector2d d = *pixel + options.noise_px * Eigen::Vector2d(n0, n1);
        double score = options.min_score + (options.max_score - options.min_score) * u_score;
        if (u_outlier < options.outlier_fraction) {
          const double r = 40 + 360 * u_dist, a = 2 * M_PI * u_angle;
          d += r * Eigen::Vector2d(std::cos(a), std::sin(a));
          score = 0.7 + 0.3 * u_score;
        }
        out.at(f, v, p, 0) = d.x();
        out.at(f, v, p, 1) = d.y();
        out.at(f, v, p, 2) = score;
      }
    }
  }
  return out;
}

}  // namespace arco::testing
