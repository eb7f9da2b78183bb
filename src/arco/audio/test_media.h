// Writes small test videos with FFmpeg's libraries (tests only): a Matroska
// file with an FFV1 (lossless) grayscale video whose frame brightness is given
// per frame, and optionally a PCM audio track.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "arco/util/status.h"

namespace arco::audio::testing {

struct TestVideo {
  int width = 160, height = 120;
  int fps = 30;
  int frames = 90;
  // Grey level (0..255) of frame k; pixels get this value plus a fixed texture.
  std::function<double(int frame)> brightness = [](int) { return 64.0; };
  // When set, draws frame k itself (row-major grey levels, width x height) and
  // `brightness` is ignored.
  std::function<void(int frame, std::vector<double>* grey)> draw;
  std::vector<float> audio;  // mono samples at audio_rate_hz; empty: no audio track
  int audio_rate_hz = 48000;
  std::string audio_codec = "pcm_s16le";  // or "flac", "aac"
};

Status WriteTestVideo(const std::string& path, const TestVideo& video);

// Two bright hands (uniform rectangles, both edges anti-aliased) on a dark textured
// background close horizontally and stop when they meet at contact_s. Each frame
// integrates its exposure [(k - 1/2)/fps, (k + 1/2)/fps) with 16 sub-samples, as a
// camera with an open shutter does; optional Gaussian sensor noise per pixel.
struct ClapScene {
  double contact_s = 3.0;      // when the hands meet (the sound of the clap)
  double speed_px_s = 150.0;   // closing speed of the gap (constant speed)
  double start_gap_px = 54.0;  // the gap while the hands rest before they move
  bool accelerate = false;     // instead: speed 10 -> 250 px/s over the last 0.4 s
  double center_x_px = 80.0, center_y_px = 60.0;  // where the hands meet
  double hand_width_px = 25.0, hand_height_px = 40.0;
  double hand_grey = 230.0, background_grey = 30.0;
  double hand_stripes_grey = 0.0;  // amplitude of stripes (fingers, creases) on the hands
  double noise_grey = 0.0;         // standard deviation of the sensor noise
  uint32_t seed = 1;
};
// Draws frame k of `scene` at `fps` into grey (width x height, row-major).
void DrawClapFrame(
    const ClapScene& scene, int fps, int k, int width, int height, std::vector<double>* grey);
// A TestVideo of `frames` frames showing `scene`.
TestVideo ClapVideo(const ClapScene& scene, int frames, int fps = 30);

}  // namespace arco::audio::testing
