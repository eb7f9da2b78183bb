// The property every calibration reader's fuzzer checks on what parses: a valid rig that
// the SPD and arco writers accept and that reads back with the same cameras, and cameras
// that project and unproject without crashing.
#pragma once

#include "arco/camera/calibration_io.h"
#include "arco/util/check.h"

inline void CheckCalibrationRoundTrip(const arco::Rig& rig) {
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
}
