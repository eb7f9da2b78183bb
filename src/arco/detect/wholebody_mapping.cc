#include "arco/detect/wholebody_mapping.h"

namespace arco::detect {

const std::array<const char*, mediapipe_pose::kNumLandmarks>& mediapipe_pose::Names() {
  static const std::array<const char*, kNumLandmarks> names = {
      "nose",        "left_eye_inner",  "left_eye",        "left_eye_outer", "right_eye_inner",
      "right_eye",   "right_eye_outer", "left_ear",        "right_ear",      "mouth_left",
      "mouth_right", "left_shoulder",   "right_shoulder",  "left_elbow",     "right_elbow",
      "left_wrist",  "right_wrist",     "left_pinky",      "right_pinky",    "left_index",
      "right_index", "left_thumb",      "right_thumb",     "left_hip",       "right_hip",
      "left_knee",   "right_knee",      "left_ankle",      "right_ankle",    "left_heel",
      "right_heel",  "left_foot_index", "right_foot_index"};
  return names;
}

const std::array<int, wholebody::kNumBody>& MediaPipeOfCocoBody() {
  // COCO: nose, left_eye, right_eye, left_ear, right_ear, left/right shoulder, elbow,
  // wrist, hip, knee, ankle.
  static const std::array<int, wholebody::kNumBody> table = {
      0, 2, 5, 7, 8, 11, 12, 13, 14, 15, 16, 23, 24, 25, 26, 27, 28};
  return table;
}

const std::array<int, wholebody::kNumFeet>& MediaPipeOfCocoFeet() {
  // COCO: left_big_toe, left_small_toe, left_heel, right_big_toe, right_small_toe,
  // right_heel.
  static const std::array<int, wholebody::kNumFeet> table = {31, -1, 29, 32, -1, 30};
  return table;
}

}  // namespace arco::detect
