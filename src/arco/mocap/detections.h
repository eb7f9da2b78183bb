// Other detectors' 2D output, as the importers read it (mocap/mmpose_json.h,
// mocap/openpose_json.h): per video frame, the people found, each with the 133
// COCO-WholeBody points (registry/keypoint_layout.h wholebody::) in the video's pixels
// (OpenCV convention, origin at the centre of the top-left pixel), NaN where the file
// has no point.
//
// One person per frame goes into a capture: SelectPerson keeps the one with the largest
// box (the file's box, else the extent of its scored points), the performer being the
// largest person in a camera's view; a tie keeps the first in the file. Scores are
// clamped into [0, 1] (RTMPose's SimCC scores exceed 1), and counted.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "arco/util/npy.h"
#include "arco/util/status.h"

namespace arco {

struct DetectedPerson {
  // wholebody::kNumPoints rows of [x_px, y_px, score]; NaN rows where nothing was given.
  std::vector<Eigen::Vector3d> keypoints;
  // [x_min, y_min, x_max, y_max] from the file; NaN when it gives none.
  Eigen::Vector4d box = Eigen::Vector4d::Constant(NAN);
  // Area of `box`, or of the extent of the points with a score above 0.
  double BoxArea() const;
};

struct DetectedFrame {
  std::vector<DetectedPerson> people;
};

// One camera's detections, indexed by its video frame (0-based): frames.size() may be
// less than the video's length when a per-video file ends early (the rest have none).
struct CameraDetections {
  std::vector<DetectedFrame> frames;
  int64_t scores_clamped = 0;  // scores outside [0, 1] clamped into it
};

// Index of the person kept (largest box, first of equals), -1 when there is none.
int SelectPerson(const DetectedFrame& frame);

// A score as stored: NaN stays NaN (no point), others clamped into [0, 1] (counted).
double ClampScore(double score, int64_t* clamped);

// The files of a per-frame folder whose names end with `suffix` (".json",
// "_keypoints.json"), in natural order (frame2 before frame10); an error naming the
// folder when it cannot be listed or holds none.
StatusOr<std::vector<std::string>> ListFrameFiles(const std::string& dir,
                                                  const std::string& suffix);

}  // namespace arco
