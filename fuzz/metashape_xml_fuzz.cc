// Fuzzes the Metashape XML calibration reader: any bytes give a rig or an error,
// never a crash; whatever parses is a valid rig that the SPD and arco writers
// accept and that reads back.
#include <cstddef>
#include <cstdint>
#include <string>

#include "arco/camera/calibration_io.h"
#include "calibration_roundtrip.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto calibration = arco::ParseMetashapeXml(text, "fuzz.xml");
  if (!calibration.ok()) return 0;
  CheckCalibrationRoundTrip(calibration->rig);
  return 0;
}
