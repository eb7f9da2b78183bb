// Fuzzes SPD's per-frame 2D keypoint reader and its summary (FrameDropIDLog) reader.
#include <cstddef>
#include <cstdint>
#include <string>

#include "arco/mocap/spd_import.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto rows = arco::ParseSpdFrame(text, "fuzz.json");
  if (rows.ok()) (void)rows->size();
  auto summary = arco::ParseSpdSummary(text, "fuzz_summary.json");
  if (summary.ok()) (void)summary->frame_drops.size();
  return 0;
}
