// Writes small test videos with an audio track (tests only), with FFmpeg's libraries: a
// Matroska file with an FFV1 (lossless) grayscale video whose frame brightness is given
// per frame, and optionally a PCM (or FLAC, AAC) audio track.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "arco/util/status.h"

namespace arco::media::testing {

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

}  // namespace arco::media::testing
