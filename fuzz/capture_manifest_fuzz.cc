// Fuzzes the capture manifest reader, then uses what it accepted.
#include <cstddef>
#include <cstdint>
#include <string>

#include "arco/mocap/capture.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto m = arco::ParseCaptureManifest(text, "fuzz/capture.json");
  if (!m.ok()) return 0;
  auto layout = m->Layout();
  (void)layout.ok();
  for (size_t v = 0; v < m->cameras.size(); ++v) {
    (void)m->VideoFrameNumber(static_cast<int>(v), m->frame_first);
  }
  (void)arco::CaptureManifestToJson(*m).dump();
  return 0;
}
