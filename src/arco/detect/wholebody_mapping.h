// MediaPipe's pose and hand landmarks in COCO-WholeBody-133 (registry/keypoint_layout.h).
//
// Body: MediaPipe's 33 pose landmarks (BlazePose topology) give COCO's 17 body points
// one to one (nose, eyes, ears, shoulders, elbows, wrists, hips, knees, ankles) and 4 of
// the 6 foot points: big toe <- foot_index (MediaPipe's tip of the foot, between the big
// and second toe), heel <- heel. MediaPipe has no small toe: left_small_toe and
// right_small_toe stay NaN, as do the 68 face points (23..90; MediaPipe's face mesh is
// not run).
// Hands: MediaPipe's 21 hand landmarks are already in hand_21 order (wrist, thumb cmc,
// mcp, ip, tip, index mcp ... little tip): left hand -> wholebody::kLeftHandFirst + i,
// right -> kRightHandFirst + i. Left and right are the person's own, as in COCO and in
// MediaPipe's pose names.
#pragma once

#include <array>

#include "arco/registry/keypoint_layout.h"

namespace arco::detect {

// MediaPipe pose landmark indices (the pose_landmark models' first 33 of 39 points).
namespace mediapipe_pose {
constexpr int kNumLandmarks = 33;
constexpr int kNumWithAuxiliary = 39;  // the model's output: 33 + 6 auxiliary points
// Auxiliary points the tracker aligns the next frame's ROI with (as pose_detection's
// keypoints 0 and 1): the hip centre and a point on the full body's enclosing circle.
constexpr int kAuxHipCentre = 33;
constexpr int kAuxBodyCircle = 34;
constexpr int kLeftWrist = 15, kRightWrist = 16;
constexpr int kLeftPinky = 17, kRightPinky = 18;
constexpr int kLeftIndex = 19, kRightIndex = 20;
// The 33 names, MediaPipe's spelling (left/right are the person's).
const std::array<const char*, kNumLandmarks>& Names();
}  // namespace mediapipe_pose

// For each COCO body point (wholebody::kBodyFirst + i, i < kNumBody) its MediaPipe
// landmark.
const std::array<int, wholebody::kNumBody>& MediaPipeOfCocoBody();
// For each COCO foot point (wholebody::kFeetFirst + i, i < kNumFeet) its MediaPipe
// landmark, -1 where MediaPipe has none (the small toes).
const std::array<int, wholebody::kNumFeet>& MediaPipeOfCocoFeet();

}  // namespace arco::detect
