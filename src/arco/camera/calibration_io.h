// Calibration readers and writers for the camera layer (no OpenCV here; the
// OpenCV YAML/XML formats and the file-level LoadCalibration/SaveCalibration
// dispatcher live in io/calibration_file.h).
//
// Every reader returns a Rig in arco's convention (camera.h): OpenCV pixel origin
// at the centre of the top-left pixel, OpenCV p1/p2 roles, x_cam = R X + t.
//
// Conversions, with f, cx, cy, b1, b2, p1, p2 as Metashape writes them and w, h the
// image size (Metashape frame model, see ../shared/docs/DOMAIN.md section 4):
//   fx = f + b1,  fy = f,  skew = b2,
//   cx_opencv = w/2 + cx - 0.5,  cy_opencv = h/2 + cy - 0.5   (corner -> pixel centre)
//   p1_opencv = p2_metashape,  p2_opencv = p1_metashape       (roles swapped)
// SPD JSON files (the dataset authors' converter output) keep Metashape's pixel
// origin in K (cx = w/2 + cx_offset) and Metashape's p1/p2 order in `distort`, so
// reading them applies the same -0.5 shift and swap; writing applies the inverse.
// All parse functions take the whole file text and a `source` name for messages,
// so fuzzers and tests call them without touching the disk.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "arco/camera/rig.h"
#include "arco/util/status.h"

namespace arco {

enum class CalibrationFormat {
  kUnknown,
  kMetashapeXml,  // Agisoft Metashape camera export (read only)
  kSpdJson,       // String Performance Dataset JSON: {"cam0": {K, R, T, imgSize, distort}}
  kArcoJson,      // arco's own JSON (same camera objects as `arco calibration show --json`)
  kOpenCvYaml,    // cv::FileStorage YAML (io layer)
  kOpenCvXml,     // cv::FileStorage XML (io layer)
};

const char* CalibrationFormatName(CalibrationFormat format);

struct Calibration {
  Rig rig;
  // Things the reader skipped or assumed, one readable line each (e.g. a camera
  // without a <transform>, i.e. not aligned by Metashape).
  std::vector<std::string> warnings;
  CalibrationFormat format = CalibrationFormat::kUnknown;
};

// Checks what every reader guarantees and every writer needs: at least one camera,
// unique non-empty names, image sides of 1..1e6 px and focal lengths, finite values,
// a proper rotation (|R^T R - I| < 1e-6, det > 0). The message names the camera.
Status ValidateCamera(const Camera& camera);
Status ValidateRig(const Rig& rig);

// Agisoft Metashape XML. Each camera uses its own sensor (`sensor_id`), the sensor's
// adjusted calibration when present; missing cx/cy/b1/b2/k/p read as 0. Cameras
// without a <transform> are skipped with a warning. A chunk <transform> (rotation,
// translation, scale), or a component <transform> in Metashape 2 files, maps the
// chunk frame to the world frame; translations are then in world units. The serial
// comes from labels "camera_SERIAL_N" (else empty). Units: "metashape".
StatusOr<Calibration> ParseMetashapeXml(const std::string& text, const std::string& source);

// SPD JSON. Serials from the SPD rig table (SpdSerialForName). Units: "metashape".
StatusOr<Calibration> ParseSpdJson(const std::string& text, const std::string& source);
// SPD JSON text. Keys: the camera name when it is "camN", else the SPD name of its
// serial, else "cam<index>". Fails on an invalid rig or a key collision.
StatusOr<std::string> WriteSpdJson(const Rig& rig);

// arco JSON: {"format": "arco-calibration", "version": 1, "units": "...",
//  "cameras": [CameraToJson(camera), ...]}.
StatusOr<Calibration> ParseArcoJson(const std::string& text, const std::string& source);
StatusOr<std::string> WriteArcoJson(const Rig& rig);

// {"name", "serial", "width", "height", "K": [9, row-major], "R": [9], "t": [3],
//  "distortion": {"k1", "k2", "k3", "p1", "p2"}} in arco's (OpenCV) convention.
nlohmann::ordered_json CameraToJson(const Camera& camera);

// The SPD rig's camera names and FLIR serials (../shared/data/spd/README.md):
// "cam0" -> "21334181", ...; empty when unknown.
std::string SpdSerialForName(const std::string& name);
// Inverse: "21334181" -> "cam0"; empty when unknown.
std::string SpdNameForSerial(const std::string& serial);

}  // namespace arco
