#include "arco/testing/plane_bow.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <random>

namespace arco::testing {

PlaneTexture MakeBowTexture(bool plain, uint32_t seed) {
  PlaneTexture bow;
  bow.image = media::MakeImage(720, 24, media::PixelFormat::kGray8);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> grey(40, 220);
  for (int by = 0; by < 24; by += 6)
    for (int bx = 0; bx < 720; bx += 6) {
      const uint8_t g = static_cast<uint8_t>(grey(rng));
      for (int y = by; y < by + 6; ++y)
        for (int x = bx; x < bx + 6; ++x) bow.image.row(y)[x] = g;
    }
  if (plain) {
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 720; ++x) {
        uint8_t g = 120;
        if (x < 60) g = (std::abs(x - 35) < 5 && std::abs(y - 12) < 5) ? 220 : 30;
        if (x >= 695) g = 235;
        bow.image.row(y)[x] = g;
      }
  }
  bow.width_mm = 720;
  bow.height_mm = 24;
  BuildMipmaps(&bow);
  return bow;
}

std::vector<Rigid3d> MakeBowingMotion(int frames, double fps_hz) {
  std::vector<Rigid3d> world_from_bow;
  const Eigen::Quaterniond rest = PlaneRestPose().rotation;
  for (int f = 0; f < frames; ++f) {
    const double t = f / fps_hz;
    const double crossing = 10 * M_PI / 180 * std::sin(2 * M_PI * 0.35 * t);
    const Eigen::Quaterniond turn(Eigen::AngleAxisd(crossing, Eigen::Vector3d::UnitY()));
    const Eigen::Vector3d axis = turn * Eigen::Vector3d::UnitX();
    const double stroke = 200 * std::sin(2 * M_PI * 0.7 * t);
    world_from_bow.emplace_back(turn * rest, Eigen::Vector3d(0, -200, -150) + stroke * axis);
  }
  return world_from_bow;
}

}  // namespace arco::testing
