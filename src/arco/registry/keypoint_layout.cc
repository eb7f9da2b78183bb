#include "arco/registry/keypoint_layout.h"

#include <map>
#include <string>

namespace arco {
namespace {

std::vector<std::string> HandNames(const std::string& prefix) {
  std::vector<std::string> n = {prefix + "wrist"};
  for (const char* j : {"cmc", "mcp", "ip", "tip"}) n.push_back(prefix + "thumb_" + j);
  for (const char* f : {"index", "middle", "ring", "little"}) {
    for (const char* j : {"mcp", "pip", "dip", "tip"}) {
      n.push_back(prefix + std::string(f) + "_" + j);
    }
  }
  return n;
}

std::vector<int> Range(int begin, int end) {
  std::vector<int> r;
  for (int i = begin; i < end; ++i) r.push_back(i);
  return r;
}

KeypointLayout Wholebody() {
  KeypointLayout l;
  l.name = "coco_wholebody_133";
  l.names = {"nose",          "left_eye",        "right_eye",    "left_ear",       "right_ear",
             "left_shoulder", "right_shoulder",  "left_elbow",   "right_elbow",    "left_wrist",
             "right_wrist",   "left_hip",        "right_hip",    "left_knee",      "right_knee",
             "left_ankle",    "right_ankle",     "left_big_toe", "left_small_toe", "left_heel",
             "right_big_toe", "right_small_toe", "right_heel"};
  for (int i = 0; i < wholebody::kNumFace; ++i) {
    l.names.push_back((i < 10 ? "face_0" : "face_") + std::to_string(i));
  }
  for (const auto& n : HandNames("left_hand_")) l.names.push_back(n);
  for (const auto& n : HandNames("right_hand_")) l.names.push_back(n);
  using namespace wholebody;
  l.groups = {{"body", Range(kBodyFirst, kBodyFirst + kNumBody)},
              {"feet", Range(kFeetFirst, kFeetFirst + kNumFeet)},
              {"face", Range(kFaceFirst, kFaceFirst + kNumFace)},
              {"left_hand", Range(kLeftHandFirst, kLeftHandFirst + kNumHandPoints)},
              {"right_hand", Range(kRightHandFirst, kRightHandFirst + kNumHandPoints)}};
  return l;
}

KeypointLayout Contact13() {
  KeypointLayout l;
  l.name = "contact_13";
  for (int s = 4; s >= 1; --s) {
    l.names.push_back("string" + std::to_string(s) + "_top");
    l.names.push_back("string" + std::to_string(s) + "_bottom");
  }
  for (const char* n : {"contact", "finger_mcp", "finger_pip", "finger_dip", "finger_tip"}) {
    l.names.push_back(n);
  }
  l.groups = {{"strings", Range(0, 8)}, {"contact", Range(8, 13)}};
  return l;
}

KeypointLayout Append(const std::string& name,
                      const KeypointLayout& base,
                      const KeypointLayout& extra) {
  KeypointLayout l = base;
  l.name = name;
  const int offset = base.size();
  l.names.insert(l.names.end(), extra.names.begin(), extra.names.end());
  for (KeypointGroup g : extra.groups) {
    for (int& i : g.indices) i += offset;
    l.groups.push_back(g);
  }
  return l;
}

KeypointLayout SpdInstrument(const std::string& name, bool cello) {
  KeypointLayout l = Wholebody();
  l.name = name;
  std::vector<std::string> extra = {"scroll_top", "nut_l", "nut_r", "bridge_l", "bridge_r"};
  if (cello) {
    extra.push_back("tail_gut");
    extra.push_back("end_pin");
  }
  extra.push_back("frog");
  extra.push_back("tip");
  const int begin = l.size();
  l.names.insert(l.names.end(), extra.begin(), extra.end());
  const int end = l.size();
  l.groups.push_back({"instrument", Range(begin, end - 2)});
  l.groups.push_back({"bow", Range(end - 2, end)});
  return l;
}

KeypointLayout Hand21() {
  KeypointLayout l;
  l.name = "hand_21";
  l.names = HandNames("");
  l.groups = {{"hand", Range(0, wholebody::kNumHandPoints)}};
  return l;
}

const std::map<std::string, KeypointLayout>& Registry() {
  static const auto* registry = [] {
    auto* m = new std::map<std::string, KeypointLayout>();
    auto add = [&](KeypointLayout l) {
      l.groups.push_back({"all", Range(0, l.size())});
      (*m)[l.name] = std::move(l);
    };
    add(Wholebody());
    add(Hand21());
    add(Contact13());
    const KeypointLayout cello = SpdInstrument("spd_cello", true);
    const KeypointLayout violin = SpdInstrument("spd_violin", false);
    add(cello);
    add(violin);
    add(Append("spd_cello_contact", cello, Contact13()));
    add(Append("spd_violin_contact", violin, Contact13()));
    return m;
  }();
  return *registry;
}

}  // namespace

int KeypointLayout::Find(const std::string& keypoint) const {
  for (size_t i = 0; i < names.size(); ++i) {
    if (names[i] == keypoint) return static_cast<int>(i);
  }
  return -1;
}

const std::vector<int>* KeypointLayout::Group(const std::string& group) const {
  for (const auto& g : groups) {
    if (g.name == group) return &g.indices;
  }
  return nullptr;
}

const KeypointLayout* FindKeypointLayout(const std::string& name) {
  const auto& r = Registry();
  const auto it = r.find(name);
  return it == r.end() ? nullptr : &it->second;
}

std::vector<std::string> KeypointLayoutNames() {
  std::vector<std::string> names;
  for (const auto& [name, layout] : Registry()) names.push_back(name);
  return names;
}

KeypointLayout MakeCustomLayout(const std::string& name, const std::vector<std::string>& names) {
  KeypointLayout l;
  l.name = name;
  l.names = names;
  l.groups.push_back({"all", Range(0, l.size())});
  return l;
}

std::string CanonicalKeypointName(const std::string& label) {
  if (label == "tip_plate") return "tip";
  return label;
}

}  // namespace arco
