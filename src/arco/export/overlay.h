// `arco overlay`: a method's 3D result drawn into one camera's view (docs/export.md,
// "Overlay"). Every point is projected with the calibration's full camera model (lens
// distortion included, Camera::ProjectToPixel), so a drawn mark sits where the camera saw
// the point. The background is the capture's video of that camera (decoded through
// media::VideoReader, turned by cameras[].rotate_deg into the calibration's image), or a
// blank frame of the calibration's image size when the camera has no video. Drawn per
// frame: the strings (nut to bridge, curved by the distortion), the skeleton (body and both
// hands), the contact point, the left fingertips with their finger numbers, and the
// sounding note's name, cents and string/finger (the method's fingering.csv).
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "arco/util/number_range.h"
#include "arco/util/status.h"

namespace arco::exporter {

inline constexpr NumberRange kOverlayScaleRange = Closed(0.05, 4);

struct OverlayOptions {
  std::string result_dir;       // an `arco run` result folder (its capture is read)
  std::string camera;           // a capture camera's name or serial
  std::string method = "arco";  // arco, paper or vision
  // Result frame numbers (result.json frames.first ...), inclusive; -1: the result's
  // first / last frame.
  int64_t first_frame = -1, last_frame = -1;
  // Output size = calibration image size x scale (rounded up to even sides for the
  // lossy codecs' 4:2:0 chroma); the drawing is scaled with it.
  double scale = 1.0;
  Status Validate() const;
};

// The marks, fixed so a reader of the video can find them (RGB, radii in output pixels).
// The left fingertips are drawn last, over everything else.
inline constexpr std::array<uint8_t, 3> kOverlayFingertipRgb = {255, 0, 255};
inline constexpr int kOverlayFingertipRadiusPx = 7;

struct OverlaySummary {
  std::string camera;  // the capture camera's name
  std::string video;   // the background video ("" : blank frames)
  std::string codec;   // the encoder used
  int width = 0, height = 0;
  double fps = 0;
  int64_t first_frame = 0, last_frame = 0;  // result frame numbers written
  int64_t frames = 0;
  int64_t frames_without_video = 0;  // frames the camera dropped (blank background)
};

// Writes the overlay video to `path` (a caller wanting an atomic output passes an
// OutputSet temporary); `container_hint` is the user's file name, whose extension picks
// the container and codec: .mp4/.mov: H.264 (libx264, else MPEG-4 part 2); .mkv: FFV1
// (lossless); .avi: MPEG-4 part 2; .webm: VP8 (libvpx), which browsers play. Errors (one line
// naming the file): no result or capture, a method the result lacks, an unknown camera, frames
// outside the result, a video that does not match its calibration camera.
StatusOr<OverlaySummary> WriteOverlay(const OverlayOptions& options,
                                      const std::string& path,
                                      const std::string& container_hint);

}  // namespace arco::exporter
