// Fuzzes the SPD JSON calibration reader (lenient JSON with NaN tokens): any bytes
// give a rig or an error, never a crash; whatever parses writes and reads back.
#include <cstddef>
#include <cstdint>
#include <string>

#include "arco/camera/calibration_io.h"
#include "calibration_roundtrip.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto calibration = arco::ParseSpdJson(text, "fuzz.json");
  (void)arco::ParseArcoJson(text, "fuzz.json");
  if (!calibration.ok()) return 0;
  CheckCalibrationRoundTrip(calibration->rig);
  return 0;
}
