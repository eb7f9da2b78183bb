#include "arco/body/skeleton.h"

namespace arco::body {
namespace {

int Add(std::vector<SkeletonJoint>& s,
        const std::string& name,
        int parent,
        bool keypoint = true,
        JointGroup group = JointGroup::kBody) {
  SkeletonJoint j;
  j.name = name;
  j.parent = parent;
  if (keypoint) j.keypoint = name;
  j.group = group;
  s.push_back(j);
  const int id = static_cast<int>(s.size()) - 1;
  if (parent >= 0) s[static_cast<size_t>(parent)].children.push_back(id);
  return id;
}

std::vector<SkeletonJoint> Build() {
  std::vector<SkeletonJoint> s;
  const int hips = Add(s, "hips", -1, false);
  s[hips].mid_a = "left_hip";
  s[hips].mid_b = "right_hip";
  for (const std::string side : {"left", "right"}) {
    int j = Add(s, side + "_hip", hips);
    j = Add(s, side + "_knee", j);
    j = Add(s, side + "_ankle", j);
    for (const char* toe : {"_big_toe", "_small_toe", "_heel"}) Add(s, side + toe, j);
  }
  const int neck = Add(s, "neck", hips, false);
  s[neck].mid_a = "left_shoulder";
  s[neck].mid_b = "right_shoulder";
  const int nose = Add(s, "nose", neck);
  for (const std::string side : {"left", "right"}) {
    const int eye = Add(s, side + "_eye", nose);
    Add(s, side + "_ear", eye);
  }
  for (const std::string side : {"left", "right"}) {
    int j = Add(s, side + "_shoulder", neck);
    j = Add(s, side + "_elbow", j);
    j = Add(s, side + "_wrist", j);
    const std::string h = side + "_hand_";
    const JointGroup hand = side == "left" ? JointGroup::kLeftHand : JointGroup::kRightHand;
    const int wrist = Add(s, h + "wrist", j, true, hand);
    s[wrist].positioned = true;
    int t = wrist;
    for (const char* joint : {"thumb_cmc", "thumb_mcp", "thumb_ip", "thumb_tip"})
      t = Add(s, h + joint, t, true, hand);
    for (const std::string finger : {"index", "middle", "ring", "little"}) {
      int f = wrist;
      for (const char* joint : {"_mcp", "_pip", "_dip", "_tip"})
        f = Add(s, h + finger + joint, f, true, hand);
    }
  }
  return s;
}

}  // namespace

const std::vector<SkeletonJoint>& WholeBodySkeleton() {
  static const std::vector<SkeletonJoint> skeleton = Build();
  return skeleton;
}

}  // namespace arco::body
