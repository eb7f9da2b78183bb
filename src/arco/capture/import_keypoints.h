// Another detector's 2D keypoints into a capture (`arco capture import-keypoints`):
// MMPose (RTMPose, RTMW, DWPose: mocap/mmpose_json.h) or OpenPose (mocap/openpose_json.h)
// output of every camera's video becomes the capture's keypoints2d.npy ((frames.count,
// cameras, layout points, 3) float32, NaN where missing, scores in [0, 1]) in the layout
// of its instrument (coco_wholebody_133, or spd_cello / spd_violin with the instrument's
// points NaN), and capture.json names it: both written together or neither
// (util/output_set.h).
//
// A camera's detections are indexed by its video frame: global frame g is video frame
// VideoFrameNumber(view, g) (docs/formats.md, "Dropped frames"), a dropped frame gets
// NaN. A folder of per-frame files must hold one file per video frame up to the
// capture's last frame; a per-video file may stop early (the rest NaN) but not go past
// it. One person per frame: the largest box (mocap/detections.h SelectPerson).
//
// Pixels: the capture's are in the calibration's image, a camera's video frames turned by
// its rotate_deg. A detector run on the decoded frames as stored (arco's VideoReader,
// ffmpeg) gives pixels that must be turned the same way (pixels = "decoded"); one run on
// frames already turned (SPD's rotated images; OpenCV, which applies a phone video's
// display rotation, the default rotate_deg) gives the calibration's pixels (pixels =
// "calibration"). With a rotated camera, pixels must be said: a guess would be a silently
// wrong capture.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "arco/util/status.h"

namespace arco::capture {

struct ImportKeypointsSource {
  std::string camera;  // the capture's camera name or serial
  std::string path;    // its detector output (file or folder)
};

struct ImportKeypointsOptions {
  std::string capture_dir;
  std::string format;                          // "mmpose" or "openpose"
  std::vector<ImportKeypointsSource> sources;  // one per camera of the capture
  bool overwrite = false;                      // replace the 2D keypoints the capture already names
  // "decoded" or "calibration" (above); may stay empty when no camera is rotated.
  std::string pixels;
  Status Validate() const;
};

struct ImportKeypointsReport {
  int64_t people_kept = 0;            // (camera, frame) pairs with a person
  int64_t frames_without_person = 0;  // recorded (camera, frame) pairs without one
  int64_t frames_with_several = 0;    // pairs with several people (the largest kept)
  int64_t scores_clamped = 0;         // scores outside [0, 1] clamped into it
};

struct ImportKeypointsSummary {
  int64_t frames = 0, views = 0, points = 0;
  std::string layout;
  ImportKeypointsReport report;
  std::vector<std::string> warnings;
};

StatusOr<ImportKeypointsSummary> ImportKeypoints(const ImportKeypointsOptions& options);

// A pixel of a decoded video frame in the frame turned clockwise by `rotate_deg` (0, 90,
// 180, 270), whose size is `rotated_size` (the calibration's image); OpenCV's pixel
// convention (centre of the top-left pixel at 0, 0).
Eigen::Vector2d RotateDecodedPixel(const Eigen::Vector2d& pixel,
                                   int rotate_deg,
                                   const Eigen::Vector2i& rotated_size);

}  // namespace arco::capture
