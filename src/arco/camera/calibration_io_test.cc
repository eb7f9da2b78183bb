// Calibration readers/writers on generated files with known truth, and on
// malformed input (every reader must return an error, never crash).
#include "arco/camera/calibration_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>

#include "arco/testing/look_at.h"

namespace arco {
namespace {

// Metashape's frame model (DOMAIN.md section 4), written independently of the
// reader: pixel with the origin at the image corner.
struct MetashapeSensor {
  int width = 2300, height = 2656;
  double f = 2261.66, cx = -5.4, cy = -8.5, b1 = 0, b2 = 0;
  double k1 = -0.08, k2 = 0.066, k3 = 0.0195, p1 = 0.0006, p2 = -0.00035;
};

Eigen::Vector2d MetashapeProject(const MetashapeSensor& s, const Eigen::Vector3d& p_cam) {
  const double x = p_cam.x() / p_cam.z(), y = p_cam.y() / p_cam.z();
  const double r2 = x * x + y * y;
  const double radial = 1 + s.k1 * r2 + s.k2 * r2 * r2 + s.k3 * r2 * r2 * r2;
  const double xd = x * radial + s.p1 * (r2 + 2 * x * x) + 2 * s.p2 * x * y;
  const double yd = y * radial + s.p2 * (r2 + 2 * y * y) + 2 * s.p1 * x * y;
  return {s.width * 0.5 + s.cx + xd * s.f + xd * s.b1 + yd * s.b2,
          s.height * 0.5 + s.cy + yd * s.f};
}

std::string Numbers(const double* v, int n) {
  std::ostringstream os;
  os.precision(17);
  for (int i = 0; i < n; ++i) os << (i ? " " : "") << v[i];
  return os.str();
}

std::string SensorXml(int id, const MetashapeSensor& s, bool with_offsets = true) {
  std::ostringstream os;
  os.precision(17);
  os << "<sensor id=\"" << id << "\" label=\"s\" type=\"frame\">"
     << "<resolution width=\"" << s.width << "\" height=\"" << s.height << "\"/>"
     << "<calibration type=\"frame\" class=\"adjusted\">"
     << "<resolution width=\"" << s.width << "\" height=\"" << s.height << "\"/>"
     << "<f>" << s.f << "</f>";
  if (with_offsets) os << "<cx>" << s.cx << "</cx><cy>" << s.cy << "</cy>";
  if (s.b1 != 0) os << "<b1>" << s.b1 << "</b1>";
  if (s.b2 != 0) os << "<b2>" << s.b2 << "</b2>";
  os << "<k1>" << s.k1 << "</k1><k2>" << s.k2 << "</k2><k3>" << s.k3 << "</k3>"
     << "<p1>" << s.p1 << "</p1><p2>" << s.p2 << "</p2></calibration></sensor>";
  return os.str();
}

// A camera-to-chunk 4x4 transform looking roughly at the origin from `center`.
Eigen::Matrix4d LookAt(const Eigen::Vector3d& center, std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  const Eigen::Vector3d target(u(*rng), u(*rng), u(*rng));
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = testing::CamFromWorldLookingAt(center, target).transpose();
  m.block<3, 1>(0, 3) = center;
  return m;
}

std::string TransformXml(const Eigen::Matrix4d& m) {
  Eigen::Matrix<double, 4, 4, Eigen::RowMajor> row_major = m;
  return "<transform>" + Numbers(row_major.data(), 16) + "</transform>";
}

struct SyntheticExport {
  std::string xml;
  std::vector<MetashapeSensor> sensors;
  std::vector<Eigen::Matrix4d> chunk_from_cam;  // of the cameras with a transform
  std::vector<int> sensor_of_camera;
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  double scale;
};

// Two sensors, cameras in groups and at top level, one unaligned camera, and a
// chunk transform with scale.
SyntheticExport MakeExport(bool chunk_transform_in_component = false) {
  SyntheticExport ex;
  std::mt19937 rng(7);
  MetashapeSensor a, b;
  b.f = 1800;
  b.cx = 3.25;
  b.cy = -1.5;
  b.b1 = 0.8;
  b.b2 = -0.3;
  b.k1 = 0.02;
  b.p1 = -0.001;
  b.p2 = 0.002;
  ex.sensors = {a, b};
  ex.rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  ex.translation = Eigen::Vector3d(0.3, -1.2, 4.0);
  ex.scale = 2.5;
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> rotation_row_major = ex.rotation;
  std::ostringstream transform;
  transform << "<transform><rotation locked=\"false\">" << Numbers(rotation_row_major.data(), 9)
            << "</rotation><translation>" << Numbers(ex.translation.data(), 3)
            << "</translation><scale>" << Numbers(&ex.scale, 1) << "</scale></transform>";
  std::ostringstream xml;
  xml << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<document version=\"2.0.0\"><chunk>"
      << "<sensors next_id=\"2\">" << SensorXml(0, a) << SensorXml(1, b) << "</sensors>"
      << "<components><component id=\"0\">" << (chunk_transform_in_component ? transform.str() : "")
      << "</component></components>"
      << "<cameras>";
  for (int i = 0; i < 5; ++i) {
    const int sensor = i % 2;
    const double angle = i * 1.1;
    const Eigen::Matrix4d m =
        LookAt(Eigen::Vector3d(2 * std::cos(angle), 2 * std::sin(angle), 0.4), &rng);
    if (i < 3) xml << "<group id=\"" << i << "\" label=\"g\">";
    xml << "<camera id=\"" << i << "\" sensor_id=\"" << sensor
        << "\" component_id=\"0\" label=\"camera_2133418" << i << "_1\">";
    if (i != 2) {
      xml << TransformXml(m);
      ex.chunk_from_cam.push_back(m);
      ex.sensor_of_camera.push_back(sensor);
    }
    xml << "</camera>";
    if (i < 3) xml << "</group>";
  }
  xml << "</cameras>" << (chunk_transform_in_component ? "" : transform.str())
      << "</chunk></document>\n";
  ex.xml = xml.str();
  return ex;
}

void ExpectMatchesMetashapeModel(const SyntheticExport& ex, const Calibration& cal) {
  ASSERT_EQ(cal.rig.cameras.size(), ex.chunk_from_cam.size());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.4, 0.4);
  for (size_t c = 0; c < cal.rig.cameras.size(); ++c) {
    const Camera& cam = cal.rig.cameras[c];
    for (int i = 0; i < 50; ++i) {
      const Eigen::Vector3d in_chunk(u(rng), u(rng), u(rng));
      const Eigen::Vector3d in_world = ex.scale * ex.rotation * in_chunk + ex.translation;
      const Eigen::Matrix4d cam_from_chunk = ex.chunk_from_cam[c].inverse();
      const Eigen::Vector3d in_cam = (cam_from_chunk * in_chunk.homogeneous()).head<3>();
      const Eigen::Vector2d expected =
          MetashapeProject(ex.sensors[ex.sensor_of_camera[c]], in_cam) - Eigen::Vector2d(0.5, 0.5);
      auto pixel = cam.Project(in_world);
      ASSERT_TRUE(pixel.has_value());
      EXPECT_NEAR((*pixel - expected).norm(), 0.0, 1e-8) << cam.name;
    }
  }
}

TEST(ParseMetashapeXml, MatchesMetashapeModelWithChunkScaleAndTwoSensors) {
  const SyntheticExport ex = MakeExport();
  auto cal = ParseMetashapeXml(ex.xml, "synthetic.xml");
  ASSERT_TRUE(cal.ok()) << cal.status().message();
  EXPECT_EQ(cal->format, CalibrationFormat::kMetashapeXml);
  EXPECT_EQ(cal->rig.units, "metashape");
  ExpectMatchesMetashapeModel(ex, *cal);
  ASSERT_EQ(cal->warnings.size(), 1u);
  EXPECT_NE(cal->warnings[0].find("camera_21334182_1"), std::string::npos);
  EXPECT_EQ(cal->rig.cameras[0].serial, "21334180");
  EXPECT_EQ(cal->rig.cameras[0].name, "camera_21334180_1");
  EXPECT_EQ(cal->rig.cameras[1].fx, 1800 + 0.8);
  EXPECT_EQ(cal->rig.cameras[1].skew, -0.3);
}

TEST(ParseMetashapeXml, ComponentTransformActsLikeChunkTransform) {
  const SyntheticExport ex = MakeExport(/*chunk_transform_in_component=*/true);
  auto cal = ParseMetashapeXml(ex.xml, "synthetic.xml");
  ASSERT_TRUE(cal.ok()) << cal.status().message();
  ExpectMatchesMetashapeModel(ex, *cal);
}

TEST(ParseMetashapeXml, MissingOffsetsMeanImageCentre) {
  MetashapeSensor s;
  const std::string xml = "<document><chunk><sensors>" + SensorXml(0, s, false) +
                          "</sensors><cameras><camera id=\"0\" sensor_id=\"0\" label=\"a\">" +
                          TransformXml(Eigen::Matrix4d::Identity()) +
                          "</camera></cameras></chunk></document>";
  auto cal = ParseMetashapeXml(xml, "x.xml");
  ASSERT_TRUE(cal.ok()) << cal.status().message();
  EXPECT_EQ(cal->rig.cameras[0].cx, 1149.5);
  EXPECT_EQ(cal->rig.cameras[0].cy, 1327.5);
  EXPECT_EQ(cal->rig.cameras[0].serial, "");
}

std::string OneCameraXml(const std::string& sensor_inner,
                         const std::string& camera_inner,
                         const std::string& chunk_extra = "") {
  return "<document><chunk><sensors><sensor id=\"0\" type=\"frame\">"
         "<resolution width=\"100\" height=\"80\"/><calibration class=\"adjusted\">" +
         sensor_inner +
         "</calibration></sensor></sensors><cameras><camera id=\"0\" sensor_id=\"0\" label=\"c\">" +
         camera_inner + "</camera></cameras>" + chunk_extra + "</chunk></document>";
}

const char* kIdentity = "<transform>1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1</transform>";

TEST(ParseMetashapeXml, MalformedInputsGiveErrors) {
  ASSERT_TRUE(ParseMetashapeXml(OneCameraXml("<f>100</f>", kIdentity), "ok.xml").ok());
  const SyntheticExport ex = MakeExport();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "malformed XML"},
      {ex.xml.substr(0, ex.xml.size() / 2), "malformed XML"},
      {"<document></document>", "no <document><chunk>"},
      {"<document><chunk/><chunk/></document>", "several <chunk>"},
      {OneCameraXml("<f>100</f>", ""), "none aligned"},
      {OneCameraXml("<f>100</f>", "<transform>1 0 0 0 0 1 0 0 0 0 1 0 0 0 0</transform>"),
       "15 numbers"},
      {OneCameraXml("<f>100</f>", "<transform>1 0 0 nan 0 1 0 0 0 0 1 0 0 0 0 1</transform>"),
       "not a list of finite numbers"},
      {OneCameraXml("<f>100</f>", "<transform>1 0 0 x 0 1 0 0 0 0 1 0 0 0 0 1</transform>"),
       "not a list of finite numbers"},
      {OneCameraXml("<f>100</f>", "<transform>1 0 0 0 0 1 0 0 0 0 1 0 0 0 1 1</transform>"),
       "0 0 0 1"},
      {OneCameraXml("<f>100</f>", "<transform>2 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1</transform>"),
       "not a proper rotation"},
      {OneCameraXml("<f>abc</f>", kIdentity), "<f> is not a list of finite numbers"},
      {OneCameraXml("<f>NaN</f>", kIdentity), "<f> is not a list"},
      {OneCameraXml("<f>-5</f>", kIdentity), "focal lengths must be positive"},
      {OneCameraXml("<cx>1</cx>", kIdentity), "has no <f>"},
      {OneCameraXml("<f>100</f><k4>0.1</k4>", kIdentity), "k4, p3 and p4"},
      {OneCameraXml("<f>100</f><k1>1 2</k1>", kIdentity), "2 numbers, expected 1"},
      {OneCameraXml("<f>100</f>", kIdentity, "<transform><scale>-1</scale></transform>"),
       "must be positive"},
      {OneCameraXml("<f>100</f>",
                    kIdentity,
                    "<transform><rotation>1 0 0 0 1 0 0 0 2</rotation></transform>"),
       "not a rotation matrix"},
      {OneCameraXml("<f>100</f>", kIdentity, "<transform/>"), "has none of"},
      {"<document><chunk><cameras><camera id=\"0\" sensor_id=\"3\">" + std::string(kIdentity) +
           "</camera></cameras></chunk></document>",
       "not defined"},
      {"<document><chunk><cameras><camera id=\"0\" sensor_id=\"x\">" + std::string(kIdentity) +
           "</camera></cameras></chunk></document>",
       "non-integer 'sensor_id'"},
      {"<document><chunk><sensors><sensor id=\"0\" type=\"fisheye\"/></sensors><cameras>"
       "<camera id=\"0\" sensor_id=\"0\">" +
           std::string(kIdentity) + "</camera></cameras></chunk></document>",
       "not supported"},
  };
  for (const auto& [text, expected] : cases) {
    auto cal = ParseMetashapeXml(text, "bad.xml");
    ASSERT_FALSE(cal.ok()) << text;
    const std::string& message = cal.status().message();
    EXPECT_EQ(message.rfind("bad.xml: ", 0), 0u) << message;
    EXPECT_NE(message.find(expected), std::string::npos) << message << "\nexpected: " << expected;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

Rig MakeRig() {
  const SyntheticExport ex = MakeExport();
  Rig rig = ParseMetashapeXml(ex.xml, "synthetic.xml")->rig;
  rig.cameras[1].name = "cam3";
  rig.cameras[2].serial = "unknown-serial";
  return rig;
}

void ExpectSameRig(const Rig& a, const Rig& b, double tolerance) {
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  EXPECT_EQ(a.units, b.units);
  for (size_t i = 0; i < a.cameras.size(); ++i) {
    const Camera& x = a.cameras[i];
    const Camera& y = b.cameras[i];
    EXPECT_EQ(x.width, y.width);
    EXPECT_EQ(x.height, y.height);
    EXPECT_LE((x.K() - y.K()).cwiseAbs().maxCoeff(), tolerance) << x.name;
    EXPECT_LE((x.cam_from_world.rotation - y.cam_from_world.rotation).cwiseAbs().maxCoeff(),
              tolerance);
    EXPECT_LE((x.cam_from_world.translation - y.cam_from_world.translation).cwiseAbs().maxCoeff(),
              tolerance);
    const Distortion& d = x.distortion;
    const Distortion& e = y.distortion;
    for (auto [u, v] :
         {std::pair{d.k1, e.k1}, {d.k2, e.k2}, {d.k3, e.k3}, {d.p1, e.p1}, {d.p2, e.p2}}) {
      EXPECT_EQ(u, v) << x.name;
    }
  }
}

TEST(SpdJson, WriteThenReadRoundTrips) {
  const Rig rig = MakeRig();
  auto text = WriteSpdJson(rig);
  ASSERT_TRUE(text.ok()) << text.status().message();
  auto back = ParseSpdJson(*text, "rt.json");
  ASSERT_TRUE(back.ok()) << back.status().message();
  // SPD keys: "cam3" kept; known serials get their SPD name (21334180 -> cam2,
  // 21334184 -> cam14); the unknown serial gets the smallest free name, cam0.
  const std::vector<std::string> expected_keys = {"cam2", "cam3", "cam0", "cam14"};
  ASSERT_EQ(back->rig.cameras.size(), rig.cameras.size());
  for (size_t i = 0; i < rig.cameras.size(); ++i) {
    const int j = back->rig.FindCamera(expected_keys[i]);
    ASSERT_GE(j, 0) << expected_keys[i];
    Rig one, other;
    one.units = other.units = "metashape";
    one.cameras = {rig.cameras[i]};
    other.cameras = {back->rig.cameras[j]};
    ExpectSameRig(one, other, 1e-12);
    EXPECT_EQ(back->rig.cameras[j].serial, SpdSerialForName(expected_keys[i]));
  }
}

TEST(ArcoJson, WriteThenReadRoundTripsExactly) {
  const Rig rig = MakeRig();
  auto text = WriteArcoJson(rig);
  ASSERT_TRUE(text.ok()) << text.status().message();
  auto back = ParseArcoJson(*text, "rt.json");
  ASSERT_TRUE(back.ok()) << back.status().message();
  ExpectSameRig(rig, back->rig, 0.0);
  for (size_t i = 0; i < rig.cameras.size(); ++i) {
    EXPECT_EQ(rig.cameras[i].name, back->rig.cameras[i].name);
    EXPECT_EQ(rig.cameras[i].serial, back->rig.cameras[i].serial);
  }
}

TEST(SpdJson, MalformedInputsGiveErrors) {
  const std::string good =
      R"({"cam0": {"K": [100, 0, 50, 0, 100, 40, 0, 0, 1], "R": [1, 0, 0, 0, 1, 0, 0, 0, 1],
        "T": [0, 0, 1], "imgSize": [100, 80], "distort": [0, 0, 0, 0, 0]}})";
  ASSERT_TRUE(ParseSpdJson(good, "ok.json").ok());
  auto with = [&](const std::string& from, const std::string& to) {
    std::string s = good;
    const size_t at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return s.replace(at, from.size(), to);
  };
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "malformed JSON"},
      {good.substr(0, 60), "malformed JSON"},
      {"[1, 2]", "must be a JSON object"},
      {"{}", "no cameras"},
      {R"({"cam0": 3})", "is not an object"},
      {with("\"K\"", "\"k\""), "has no \"K\""},
      {with("[100, 0, 50,", "[100, 0,"), "8 numbers, expected 9"},
      {with("\"T\": [0, 0, 1]", "\"T\": [0, NaN, 1]"), "non-number (null)"},
      {with("\"T\": [0, 0, 1]", "\"T\": [0, \"a\", 1]"), "non-number (string)"},
      {with("[100, 80]", "[100.5, 80]"), "two positive integers"},
      {with("[100, 80]", "[0, 80]"), "two positive integers"},
      {with("0, 0, 1], \"R\"", "0, 1, 1], \"R\""), "not an intrinsic matrix"},
      {with("[1, 0, 0, 0, 1, 0, 0, 0, 1]", "[1, 0, 0, 0, 1, 0, 0, 0, -1]"),
       "not a proper rotation"},
      {with("[100, 0, 50", "[-100, 0, 50"), "focal lengths must be positive"},
      {with("\"distort\": [0, 0, 0, 0, 0]", "\"distort\": [0, 0, 0]"), "3 numbers"},
      {with("[0, 0, 1]", "[0, 0, 1e400]"), "malformed JSON"},
  };
  for (const auto& [text, expected] : cases) {
    auto cal = ParseSpdJson(text, "bad.json");
    ASSERT_FALSE(cal.ok()) << text;
    const std::string& message = cal.status().message();
    EXPECT_EQ(message.rfind("bad.json: ", 0), 0u) << message;
    EXPECT_NE(message.find(expected), std::string::npos) << message << "\nexpected: " << expected;
  }
}

TEST(ArcoJson, MalformedInputsGiveErrors) {
  const std::string good = *WriteArcoJson(MakeRig());
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"{}", "no \"cameras\" array"},
      {R"({"cameras": []})", "no cameras"},
      {R"({"format": "other", "cameras": []})", "\"format\""},
      {R"({"version": 2, "cameras": []})", "unsupported \"version\""},
      {R"({"cameras": [{"name": 1}]})", "no string \"name\""},
      {R"({"cameras": [{"name": "a", "width": 10.5}]})", "no integer \"width\""},
      {R"({"cameras": [{"name": "a", "width": 10, "height": 10, "K": [1]}]})", "1 numbers"},
      {good.substr(0, good.size() - 10), "malformed JSON"},
  };
  for (const auto& [text, expected] : cases) {
    auto cal = ParseArcoJson(text, "bad.json");
    ASSERT_FALSE(cal.ok()) << text;
    EXPECT_NE(cal.status().message().find(expected), std::string::npos)
        << cal.status().message() << "\nexpected: " << expected;
  }
}

TEST(Writers, RejectInvalidRigs) {
  Rig rig = MakeRig();
  rig.cameras[1].name = rig.cameras[0].name;
  EXPECT_FALSE(WriteArcoJson(rig).ok());
  EXPECT_FALSE(WriteSpdJson(Rig{}).ok());
  rig = MakeRig();
  rig.cameras[0].fx = std::nan("");
  EXPECT_FALSE(WriteSpdJson(rig).ok());
}

TEST(ValidateCamera, NamesMustBePrintableUtf8) {
  Camera cam = MakeRig().cameras[0];
  for (const std::string name : {"cam\xCD", "a\nb", "\xC0\xAF", "x\xE2\x82", "\xED\xA0\x80"}) {
    cam.name = name;
    EXPECT_FALSE(ValidateCamera(cam).ok()) << name;
  }
  for (const std::string name : {"caméra 1", "カメラ", "a: \"b\" {c} [d] #e", "\xF0\x9F\x8E\xBB"}) {
    cam.name = name;
    EXPECT_TRUE(ValidateCamera(cam).ok()) << name;
  }
  cam.serial = "12\x01";
  EXPECT_FALSE(ValidateCamera(cam).ok());
}

TEST(SpdRigTable, MapsNamesAndSerialsBothWays) {
  EXPECT_EQ(SpdSerialForName("cam0"), "21334181");
  EXPECT_EQ(SpdSerialForName("cam19"), "21334211");
  EXPECT_EQ(SpdSerialForName("cam23"), "21334210");
  EXPECT_EQ(SpdSerialForName("cam24"), "");
  EXPECT_EQ(SpdSerialForName("cam01"), "");
  EXPECT_EQ(SpdSerialForName("camera"), "");
  for (int i = 0; i < 24; ++i) {
    const std::string name = "cam" + std::to_string(i);
    EXPECT_EQ(SpdNameForSerial(SpdSerialForName(name)), name);
  }
}

}  // namespace
}  // namespace arco
