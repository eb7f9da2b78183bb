// Test scenes for sync (tests only): a clap filmed and heard, as a TestVideo that
// media/test_audio_video.h writes (an FFV1 grayscale video and an audio track).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "arco/media/test_audio_video.h"
#include "arco/util/status.h"

namespace arco::audio::testing {

// The videos themselves are written by media/'s test support, the one owner of FFmpeg.
using media::testing::TestVideo;
using media::testing::WriteTestVideo;

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
