// Fuzzes the SPD JSON calibration reader (lenient JSON with NaN tokens): any bytes
// give a rig or an error, never a crash; whatever parses writes and reads back.
#include <cstddef>
#include <cstdint>
#include <string>

#include "arco/camera/calibration_io.h"
#include "arco/util/check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto calibration = arco::ParseSpdJson(text, "fuzz.json");
  (void)arco::ParseArcoJson(text, "fuzz.json");
  if (!calibration.ok()) return 0;
  const arco::Rig& rig = calibration->rig;
  ARCO_CHECK(arco::ValidateRig(rig).ok());
  auto spd = arco::WriteSpdJson(rig);
  ARCO_CHECK(spd.ok()) << spd.status().message();
  auto back = arco::ParseSpdJson(*spd, "roundtrip.json");
  ARCO_CHECK(back.ok()) << back.status().message();
  ARCO_CHECK(back->rig.cameras.size() == rig.cameras.size());
  auto arco_json = arco::WriteArcoJson(rig);
  ARCO_CHECK(arco_json.ok()) << arco_json.status().message();
  ARCO_CHECK(arco::ParseArcoJson(*arco_json, "roundtrip.json").ok());
  for (const arco::Camera& camera : rig.cameras) {
    (void)camera.Project(Eigen::Vector3d(0.1, 0.2, 0.3));
    (void)camera.PixelToNormalized(Eigen::Vector2d(camera.cx + 10, camera.cy - 5));
  }
  return 0;
}
