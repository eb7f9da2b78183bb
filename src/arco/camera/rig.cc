#include "arco/camera/rig.h"

namespace arco {

int Rig::FindCamera(const std::string& id) const {
  for (size_t i = 0; i < cameras.size(); ++i) {
    if (cameras[i].name == id || (!cameras[i].serial.empty() && cameras[i].serial == id)) {
      return static_cast<int>(i);
    }
  }
  return -1;
}

}  // namespace arco
