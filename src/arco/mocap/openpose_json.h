// Reader of OpenPose's JSON output (--write_json: one FRAME_keypoints.json per frame)
// into CameraDetections (mocap/detections.h):
//
//   {"version": 1.3, "people": [{"pose_keypoints_2d": [x, y, c, ...] x 25 (BODY_25),
//     "face_keypoints_2d": [...] x 70, "hand_left_keypoints_2d": [...] x 21,
//     "hand_right_keypoints_2d": [...] x 21, ...}, ...]}
//
// BODY_25's points go to COCO-WholeBody's by name (its neck and mid hip have no slot);
// the hands' 21 points are already in hand_21 order (wrist, thumb 1-4, index 1-4, ...)
// and go to the left and right hand slots (OpenPose's left hand is the person's, as in
// COCO-WholeBody); the face's first 68 points are the same 68-point face as
// COCO-WholeBody's (its two pupils are dropped). OpenPose writes an undetected point as
// 0, 0, 0: a confidence of 0 is a missing point (NaN). Empty arrays are allowed (a part
// not detected or not requested); any other length is an error naming the file and the
// field ("people[0].pose_keypoints_2d has 74 values; expected 75 (25 x [x, y, c])").
// A COCO-18 pose (18 points, OpenPose's COCO model) is read too.
#pragma once

#include <string>

#include "arco/mocap/detections.h"
#include "arco/util/status.h"

namespace arco {

// One FRAME_keypoints.json.
StatusOr<DetectedFrame> ParseOpenPoseFrame(const std::string& text, const std::string& source);

// A folder of *_keypoints.json files in natural order (file k = video frame k), or a
// single file (one frame).
StatusOr<CameraDetections> ReadOpenPoseKeypoints(const std::string& path);

}  // namespace arco
