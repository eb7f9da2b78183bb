#include "arco/audio/test_media.h"

#include <algorithm>
#include <cmath>
#include <random>

namespace arco::audio::testing {
namespace {

// Length of [a, b] inside the pixel [x - 1/2, x + 1/2].
double Coverage(double a, double b, int x) {
  return std::max(0.0, std::min(b, x + 0.5) - std::max(a, x - 0.5));
}

// The gap between the hands `before_s` seconds before contact (0 after it).
double Gap(const ClapScene& s, double before_s) {
  if (before_s <= 0) return 0.0;
  if (!s.accelerate) return std::min(s.start_gap_px, s.speed_px_s * before_s);
  const double b = std::min(before_s, 0.4);
  return 250.0 * b - 300.0 * b * b + 10.0 * (before_s - b);
}

}  // namespace

void DrawClapFrame(
    const ClapScene& s, int fps, int k, int width, int height, std::vector<double>* grey) {
  grey->assign(static_cast<size_t>(width) * height, 0.0);
  constexpr int kSub = 16;
  std::vector<double> column(static_cast<size_t>(width)), shade(column);
  for (int sub = 0; sub < kSub; ++sub) {
    const double t = (k - 0.5 + (sub + 0.5) / kSub) / fps;
    const double half = Gap(s, s.contact_s - t) / 2.0;
    const double left_in = s.center_x_px - half, right_in = s.center_x_px + half;
    for (int x = 0; x < width; ++x) {
      const double left = Coverage(left_in - s.hand_width_px, left_in, x);
      const double right = Coverage(right_in, right_in + s.hand_width_px, x);
      column[x] = std::min(1.0, left + right);
      // Stripes 5 px apart that move with each hand (position relative to its inner edge).
      const double u = left >= right ? left_in - x : x - right_in;
      shade[x] = s.hand_grey + s.hand_stripes_grey * std::sin(2.0 * M_PI * u / 5.0);
    }
    for (int y = 0; y < height; ++y) {
      const double rows =
          Coverage(s.center_y_px - s.hand_height_px / 2, s.center_y_px + s.hand_height_px / 2, y);
      for (int x = 0; x < width; ++x) {
        const double texture = 12.0 * (((x / 6) + (y / 6)) % 2);
        const double background = s.background_grey + texture;
        const double c = rows * column[x];
        (*grey)[static_cast<size_t>(y) * width + x] +=
            (c * shade[x] + (1.0 - c) * background) / kSub;
      }
    }
  }
  if (s.noise_grey > 0) {
    std::mt19937 rng(s.seed * 7919u + static_cast<uint32_t>(k));
    std::normal_distribution<double> gauss(0.0, s.noise_grey);
    for (double& v : *grey) v += gauss(rng);
  }
}

TestVideo ClapVideo(const ClapScene& scene, int frames, int fps) {
  TestVideo video;
  video.frames = frames;
  video.fps = fps;
  video.draw = [scene, fps, w = video.width, h = video.height](int k, std::vector<double>* grey) {
    DrawClapFrame(scene, fps, k, w, h, grey);
  };
  return video;
}

}  // namespace arco::audio::testing
