// Fuzzes the labelme reader: any bytes give an annotation or an error, never a crash.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "arco/mocap/labelme.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto a = arco::ParseLabelme(text, "fuzz.json");
  if (a.ok()) {
    for (const auto& p : a->points) {
      if (!p.pixel.allFinite() || p.label.empty()) std::abort();  // the reader's promise
    }
  }
  return 0;
}
