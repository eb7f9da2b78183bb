// The timestamps a video file gives its frames, read from the container's packets
// (no decoding): what `arco capture new` checks before it lays a video on the capture's
// regular timeline (issue 26, part 2: variable frame rate).
//
// media::VideoReader shows frame n at n / fps as a constant-rate player does: a gap in
// the timestamps repeats the previous picture. A phone's variable-rate video jitters by
// a fraction of a frame, which that absorbs; a jump of a frame period or more (a pause,
// dropped frames, a cut) would be stretched over silently, so it is reported.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "arco/util/status.h"

namespace arco::media {

// A step between consecutive timestamps (in presentation order) this many frame
// periods long or more is a jump.
inline constexpr double kTimestampJumpPeriods = 1.5;

struct TimestampJump {
  double at_s = 0;    // the timestamp after the jump, from the first frame's
  double step_s = 0;  // the step (one frame period would be 1 / fps)
};

struct FrameTimes {
  double fps = 0;              // the stream's nominal rate (0 when unknown)
  std::vector<double> time_s;  // every frame's timestamp from the first's, sorted
  std::vector<TimestampJump> jumps;
  double min_step_s = 0, max_step_s = 0;  // between consecutive frames
};

// Errors name the file (unreadable, no video stream). Frames without timestamps are
// left out (a file with none gives an empty time_s).
StatusOr<FrameTimes> ReadFrameTimes(const std::string& path);

// One line about the jumps ("" when none): "FILE: timestamps jump N times (the largest
// by X s at Y s): ...".
std::string DescribeTimestampJumps(const std::string& path, const FrameTimes& times);

}  // namespace arco::media
