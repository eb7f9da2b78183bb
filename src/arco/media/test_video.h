// Writes small test videos whose frames show their own index (tests only), with
// FFmpeg's libraries: frame k carries k in binary as a grid of dark/bright blocks,
// large enough to survive lossy codecs, so a test can check which frame it got.
#pragma once

#include <functional>
#include <string>

#include "arco/media/image.h"
#include "arco/media/video_reader.h"
#include "arco/util/status.h"

namespace arco::media::testing {

struct IndexVideo {
  std::string container = "matroska";  // libavformat muxer name: "matroska", "mp4", "avi"
  std::string codec = "ffv1";          // encoder name: "ffv1", "mpeg4", "libx264", ...
  int width = 128, height = 96;        // multiples of the 32 px blocks
  Rational fps{30, 1};
  int frames = 60;
  int gop = 12;          // key frame interval
  int b_frames = 0;      // B-frames between references (reordered pts)
  int rotation_deg = 0;  // clockwise display rotation, written as a display matrix
};

// Frame k of an index video (gray), as encoded.
Image IndexFrame(const IndexVideo& video, int k);
// The index shown in a decoded frame (any format or size scale), or -1.
int ReadIndex(const Image& frame);

Status WriteIndexVideo(const std::string& path, const IndexVideo& video);
// The same container, codec and timing with the frames `frame(k)` (gray, video.width x
// video.height) instead of index frames: e.g. rendered calibration-board views.
Status WriteGrayVideo(const std::string& path,
                      const IndexVideo& video,
                      const std::function<Image(int)>& frame);
// Frame k of `video` alone as a grayscale PNG file.
Status WriteIndexPng(const std::string& path, const IndexVideo& video, int k);

// Whether this FFmpeg build has the encoder (libx264 is optional).
bool HasEncoder(const std::string& name);

}  // namespace arco::media::testing
