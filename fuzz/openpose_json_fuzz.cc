// Fuzzes the OpenPose frame reader: any bytes give people or an error, never a crash;
// every person it returns has the 133 COCO-WholeBody rows, scores in (0, 1].
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "arco/mocap/openpose_json.h"
#include "arco/registry/keypoint_layout.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto frame = arco::ParseOpenPoseFrame(text, "fuzz_keypoints.json");
  if (frame.ok()) {
    for (const auto& person : frame->people) {
      if (person.keypoints.size() != static_cast<size_t>(arco::wholebody::kNumPoints)) {
        std::abort();
      }
      for (const auto& p : person.keypoints) {
        if (p.allFinite() && !(p.z() > 0 && p.z() <= 1)) std::abort();  // the promise
      }
    }
  }
  return 0;
}
