// The real SPD calibrations (../shared/data/spd): the Metashape XML exports
// against the dataset authors' JSON conversions of the same sessions.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "arco/camera/calibration_io.h"
#include "arco/util/file_io.h"
#include "arco/util/json_io.h"

namespace arco {
namespace {

std::string SpdPath(const std::string& name) {
  return std::string(ARCO_SHARED_DATA_DIR) + "/spd/" + name;
}

Calibration Read(const std::string& name) {
  auto text = ReadFileToString(SpdPath(name));
  EXPECT_TRUE(text.ok()) << text.status().message();
  if (!text.ok()) return {};
  auto cal = name.find(".xml") != std::string::npos ? ParseMetashapeXml(*text, name)
                                                    : ParseSpdJson(*text, name);
  EXPECT_TRUE(cal.ok()) << cal.status().message();
  return cal.ok() ? *cal : Calibration{};
}

struct Differences {
  double rotation = 0, translation = 0, focal_px = 0, principal_px = 0, distortion = 0;
};

// Compares the XML rig with the JSON rig camera by camera (matched by serial).
// `raw_json` is the JSON file itself, for the K it stores (Metashape pixel origin).
Differences CompareXmlWithJson(const std::string& xml_name, const std::string& json_name) {
  const Calibration xml = Read(xml_name);
  const Calibration json = Read(json_name);
  Differences max;
  EXPECT_EQ(xml.rig.cameras.size(), 20u);
  EXPECT_EQ(json.rig.cameras.size(), 20u);
  auto raw = ReadJsonFile(SpdPath(json_name));
  EXPECT_TRUE(raw.ok());
  if (!raw.ok()) return max;
  for (const Camera& x : xml.rig.cameras) {
    EXPECT_FALSE(x.serial.empty()) << x.name;
    EXPECT_EQ(x.name, "camera_" + x.serial + "_1");
    const int j = json.rig.FindCamera(x.serial);
    if (j < 0) {
      ADD_FAILURE() << "serial " << x.serial << " of " << x.name << " is not in " << json_name;
      continue;
    }
    const Camera& y = json.rig.cameras[j];
    EXPECT_EQ(x.width, y.width);
    EXPECT_EQ(x.height, y.height);
    auto track = [](double* m, double v) { *m = std::max(*m, std::abs(v)); };
    track(&max.rotation,
          (x.cam_from_world.rotation - y.cam_from_world.rotation).cwiseAbs().maxCoeff());
    track(&max.translation,
          (x.cam_from_world.translation - y.cam_from_world.translation).cwiseAbs().maxCoeff());
    track(&max.focal_px, std::max(std::abs(x.fx - y.fx), std::abs(x.fy - y.fy)));
    track(&max.principal_px, std::max(std::abs(x.cx - y.cx), std::abs(x.cy - y.cy)));
    const Distortion& a = x.distortion;
    const Distortion& b = y.distortion;
    for (double d : {a.k1 - b.k1, a.k2 - b.k2, a.k3 - b.k3, a.p1 - b.p1, a.p2 - b.p2}) {
      track(&max.distortion, d);
    }
    // The JSON's own K keeps Metashape's corner origin: exactly 0.5 px from ours.
    const Json& k = (*raw)[y.name]["K"];
    EXPECT_NEAR(k[2].get<double>() - x.cx, 0.5, 1e-9) << x.name;
    EXPECT_NEAR(k[5].get<double>() - x.cy, 0.5, 1e-9) << x.name;
    EXPECT_EQ(k[0].get<double>(), x.fx);
  }
  std::printf("%s vs %s: max |dR| %.3g, |dt| %.3g, |df| %.3g px, |dc| %.3g px, |d dist| %.3g\n",
              xml_name.c_str(),
              json_name.c_str(),
              max.rotation,
              max.translation,
              max.focal_px,
              max.principal_px,
              max.distortion);
  return max;
}

TEST(RealCalibration, ScaleSessionXmlAgreesWithAuthorsJson) {
  const Differences d =
      CompareXmlWithJson("cello_1113_scale_camera.xml", "cello_1113_scale_camera.json");
  // Same numbers up to float64 rounding in the authors' converter (R transposed,
  // T = -R C): no chunk transform/scale in this file, so ignoring it changed nothing.
  EXPECT_LT(d.rotation, 1e-12);
  EXPECT_LT(d.translation, 1e-12);
  EXPECT_LT(d.focal_px, 1e-9);
  EXPECT_LT(d.principal_px, 1e-9);
  EXPECT_EQ(d.distortion, 0.0);
}

TEST(RealCalibration, CameraSessionXmlAgreesWithAuthorsJson) {
  const Differences d = CompareXmlWithJson("camera.xml", "camera.json");
  EXPECT_LT(d.rotation, 1e-12);
  EXPECT_LT(d.translation, 1e-12);
  EXPECT_LT(d.focal_px, 1e-9);
  EXPECT_LT(d.principal_px, 1e-9);
  EXPECT_EQ(d.distortion, 0.0);
}

TEST(RealCalibration, ScaleSessionHasNoChunkTransformAndOneSensor) {
  // Why ignoring the chunk scale did not matter for the authors: there is none.
  auto text = ReadFileToString(SpdPath("cello_1113_scale_camera.xml"));
  ASSERT_TRUE(text.ok());
  EXPECT_EQ(text->find("<scale>"), std::string::npos);
  EXPECT_EQ(text->find("<rotation>"), std::string::npos);
  const Calibration cal = Read("cello_1113_scale_camera.xml");
  EXPECT_TRUE(cal.warnings.empty());
  EXPECT_EQ(cal.rig.units, "metashape");
  for (const Camera& cam : cal.rig.cameras) {
    EXPECT_EQ(cam.fx, 2261.6599385609247);
    EXPECT_EQ(cam.cx, 1150 - 5.3966724789809142 - 0.5);
    EXPECT_EQ(cam.cy, 1328 - 8.532430251414155 - 0.5);
    EXPECT_EQ(cam.distortion.p1, -0.00035459105413522914);  // Metashape p2
    EXPECT_EQ(cam.distortion.p2, 0.00061819887765959857);   // Metashape p1
  }
}

TEST(RealCalibration, PgySessionPrincipalPointIsImageCentre) {
  const Calibration cal = Read("cello_1113_pgy_camera.xml");
  ASSERT_EQ(cal.rig.cameras.size(), 20u);
  for (const Camera& cam : cal.rig.cameras) {
    EXPECT_EQ(cam.width, 2300);
    EXPECT_EQ(cam.height, 2656);
    // Image centre in OpenCV's pixel-centre convention: (w - 1) / 2, (h - 1) / 2.
    EXPECT_EQ(cam.cx, 1149.5);
    EXPECT_EQ(cam.cy, 1327.5);
    EXPECT_EQ(cam.fx, 2263.3541164824833);
    EXPECT_EQ(cam.distortion.k1, 0.0);
    EXPECT_EQ(cam.distortion.k2, 0.0);
    EXPECT_EQ(cam.distortion.k3, 0.0);
    EXPECT_EQ(cam.distortion.p1, -0.0028066606109962739);
    EXPECT_EQ(cam.distortion.p2, 0.0016516607053477337);
  }
}

TEST(RealCalibration, RigCentresSurroundThePerformer) {
  // A sanity property of the real rig: every camera sees the rig's centroid in
  // front of it and inside its image.
  for (const char* name :
       {"cello_1113_scale_camera.xml", "camera.xml", "cello_1113_pgy_camera.xml"}) {
    const Calibration cal = Read(name);
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const Camera& cam : cal.rig.cameras) centroid += cam.CenterInWorld();
    centroid /= cal.rig.cameras.size();
    for (const Camera& cam : cal.rig.cameras) {
      auto pixel = cam.Project(centroid);
      ASSERT_TRUE(pixel.has_value()) << name << " " << cam.name;
      EXPECT_GT(pixel->x(), 0);
      EXPECT_LT(pixel->x(), cam.width);
      EXPECT_GT(pixel->y(), 0);
      EXPECT_LT(pixel->y(), cam.height);
    }
  }
}

TEST(RealCalibration, UndistortionRoundTripsOverTheWholeImage) {
  // Every pixel of every real camera (grid incl. the corners) maps to a normalised
  // point that projects back onto it: the Gauss-Newton undistortion converges.
  for (const char* name :
       {"cello_1113_scale_camera.xml", "camera.xml", "cello_1113_pgy_camera.xml"}) {
    const Calibration cal = Read(name);
    for (const Camera& cam : cal.rig.cameras) {
      double worst_px = 0;
      for (int i = 0; i <= 20; ++i) {
        for (int j = 0; j <= 20; ++j) {
          const Eigen::Vector2d pixel(-0.5 + cam.width * i / 20.0, -0.5 + cam.height * j / 20.0);
          const Eigen::Vector2d n = cam.PixelToNormalized(pixel);
          double xd, yd;
          cam.Distort(n.x(), n.y(), &xd, &yd);
          const Eigen::Vector2d back(cam.fx * xd + cam.skew * yd + cam.cx, cam.fy * yd + cam.cy);
          worst_px = std::max(worst_px, (back - pixel).norm());
        }
      }
      EXPECT_LT(worst_px, 1e-6) << name << " " << cam.name;
    }
  }
}

TEST(RealCalibration, RadialDistortionMovesEdgePointsByFifteenToTwentyPixels) {
  // DOMAIN.md section 4: k1 about -0.08 moves points near the image edge by 15-20 px.
  const Calibration cal = Read("cello_1113_scale_camera.xml");
  const Camera& cam = cal.rig.cameras[0];
  // "Near the edge": 50 px inside the left and right borders, on the principal row.
  const Eigen::Vector2d left(50.0, cam.cy), right(cam.width - 51.0, cam.cy);
  for (const Eigen::Vector2d& pixel : {left, right}) {
    const double shift = (cam.UndistortPixel(pixel) - pixel).norm();
    std::printf("undistortion shift at (%.0f, %.0f): %.2f px\n", pixel.x(), pixel.y(), shift);
    EXPECT_GT(shift, 15.0);
    EXPECT_LT(shift, 20.0);
  }
}

TEST(RealCalibration, SpdWriterReproducesAuthorsJson) {
  // Our SPD writer applied to the XML gives the authors' file, key by key.
  const Calibration xml = Read("cello_1113_scale_camera.xml");
  auto written = WriteSpdJson(xml.rig);
  ASSERT_TRUE(written.ok()) << written.status().message();
  auto ours = ParseJsonLenient(*written, "written");
  auto theirs = ReadJsonFile(SpdPath("cello_1113_scale_camera.json"));
  ASSERT_TRUE(ours.ok() && theirs.ok());
  ASSERT_EQ(ours->size(), theirs->size());
  for (auto it = theirs->begin(); it != theirs->end(); ++it) {
    ASSERT_TRUE(ours->contains(it.key())) << it.key();
    for (const char* field : {"K", "R", "T", "imgSize", "distort"}) {
      const Json& a = (*ours)[it.key()][field];
      const Json& b = it.value()[field];
      ASSERT_EQ(a.size(), b.size()) << it.key() << " " << field;
      for (size_t i = 0; i < a.size(); ++i) {
        EXPECT_NEAR(a[i].get<double>(), b[i].get<double>(), 1e-12) << it.key() << " " << field;
      }
    }
  }
}

}  // namespace
}  // namespace arco
