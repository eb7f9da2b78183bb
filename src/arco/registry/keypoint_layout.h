// Named keypoint layouts, so arrays of keypoints carry meaning and SPD data
// round-trips (DOMAIN.md section 3):
//   coco_wholebody_133   0-16 body, 17-22 feet, 23-90 face (68), 91-111 left hand,
//                        112-132 right hand (hand order below)
//   hand_21              wrist; thumb cmc, mcp, ip, tip; index/middle/ring/little
//                        mcp, pip, dip, tip (MediaPipe order)
//   spd_cello            133 + scroll_top, nut_l, nut_r, bridge_l, bridge_r, tail_gut,
//                        end_pin, frog, tip (142)
//   spd_violin           133 + scroll_top, nut_l, nut_r, bridge_l, bridge_r, frog, tip (140)
//   contact_13           string4_top, string4_bottom, ... string1_bottom (lowest string
//                        first), contact, finger_mcp, finger_pip, finger_dip, finger_tip
//   spd_cello_contact    spd_cello + contact_13 (155), as SPD's released results
//   spd_violin_contact   spd_violin + contact_13 (153)
// Groups name index ranges ("body", "feet", "face", "left_hand", "right_hand",
// "instrument", "bow", "strings", "contact") for per-group processing such as
// temporal filters; "all" covers every point.
//
// This is the one place that knows the offsets: code that indexes a COCO-WholeBody array
// (or an spd_* array, which starts with one) uses the wholebody:: constants below or
// looks a group up; a test checks that both agree with the names.
#pragma once

#include <string>
#include <vector>

namespace arco {

// COCO-WholeBody-133 index ranges (DOMAIN.md section 3). Hands in hand_21 order.
namespace wholebody {
constexpr int kBodyFirst = 0;  // nose .. right_ankle
constexpr int kNumBody = 17;
constexpr int kLeftShoulder = 5;  // where the performer's back is (instrument stage)
constexpr int kRightShoulder = 6;
constexpr int kLeftWrist = 9;  // the body's wrists: the hands' wrists exactly
constexpr int kRightWrist = 10;
constexpr int kFeetFirst = 17;  // left_big_toe .. right_heel
constexpr int kNumFeet = 6;
constexpr int kFaceFirst = 23;  // face_00 .. face_67
constexpr int kNumFace = 68;
constexpr int kNumHandPoints = 21;  // the hand_21 layout
constexpr int kLeftHandFirst = 91;  // left_hand_wrist
constexpr int kRightHandFirst = 112;
constexpr int kNumPoints = 133;  // also where an spd_* layout's instrument points begin
static_assert(kFeetFirst == kBodyFirst + kNumBody && kFaceFirst == kFeetFirst + kNumFeet &&
                  kLeftHandFirst == kFaceFirst + kNumFace &&
                  kRightHandFirst == kLeftHandFirst + kNumHandPoints &&
                  kNumPoints == kRightHandFirst + kNumHandPoints,
              "COCO-WholeBody ranges must tile 0..133");
}  // namespace wholebody

struct KeypointGroup {
  std::string name;
  std::vector<int> indices;
};

struct KeypointLayout {
  std::string name;
  std::vector<std::string> names;
  std::vector<KeypointGroup> groups;

  int size() const { return static_cast<int>(names.size()); }
  // Index of a keypoint name, -1 when absent.
  int Find(const std::string& keypoint) const;
  // Indices of a group ("all" for every point); nullptr when the group is unknown.
  const std::vector<int>* Group(const std::string& group) const;
};

// The built-in layout with this name, or nullptr.
const KeypointLayout* FindKeypointLayout(const std::string& name);
std::vector<std::string> KeypointLayoutNames();

// A layout from explicit names (e.g. labelme labels): one group "all".
KeypointLayout MakeCustomLayout(const std::string& name, const std::vector<std::string>& names);

// Label aliases used by SPD's labelme files for layout names ("tip_plate" -> "tip").
std::string CanonicalKeypointName(const std::string& label);

}  // namespace arco
