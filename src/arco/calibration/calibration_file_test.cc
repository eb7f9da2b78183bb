// LoadCalibration/SaveCalibration: format detection, read -> write -> read round
// trips for every writer (on the real SPD calibration), malformed files.
#include "arco/calibration/calibration_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"

namespace arco::calibration {
namespace {

namespace fs = std::filesystem;

std::string SpdPath(const std::string& name) {
  return std::string(ARCO_SHARED_DATA_DIR) + "/spd/" + name;
}

// A fresh folder per test, removed afterwards (parameterised names included).
class WithTempDir : public ::testing::Test {
 protected:
  std::string Path(const std::string& name) const { return dir_ / name; }
  testing::TempDir dir_;
};

void ExpectSameRig(const Rig& a, const Rig& b, double tolerance, bool names_kept) {
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  EXPECT_EQ(a.units, b.units);
  for (const Camera& x : a.cameras) {
    const int j = b.FindCamera(x.serial);
    ASSERT_GE(j, 0) << x.serial;
    const Camera& y = b.cameras[j];
    if (names_kept) {
      EXPECT_EQ(x.name, y.name);
    }
    EXPECT_EQ(x.width, y.width);
    EXPECT_EQ(x.height, y.height);
    EXPECT_LE((x.K() - y.K()).cwiseAbs().maxCoeff(), tolerance) << x.name;
    EXPECT_LE((x.cam_from_world.rotation - y.cam_from_world.rotation).cwiseAbs().maxCoeff(),
              tolerance);
    EXPECT_LE((x.cam_from_world.translation - y.cam_from_world.translation).cwiseAbs().maxCoeff(),
              tolerance);
    EXPECT_EQ(x.distortion.k1, y.distortion.k1);
    EXPECT_EQ(x.distortion.k2, y.distortion.k2);
    EXPECT_EQ(x.distortion.k3, y.distortion.k3);
    EXPECT_EQ(x.distortion.p1, y.distortion.p1);
    EXPECT_EQ(x.distortion.p2, y.distortion.p2);
  }
}

TEST(DetectCalibrationFormat, RecognisesEachFormat) {
  EXPECT_EQ(DetectCalibrationFormat("<?xml version=\"1.0\"?>\n<document/>"),
            CalibrationFormat::kMetashapeXml);
  EXPECT_EQ(DetectCalibrationFormat("\xEF\xBB\xBF<?xml version=\"1.0\"?>\n<opencv_storage>"),
            CalibrationFormat::kOpenCvXml);
  EXPECT_EQ(DetectCalibrationFormat("%YAML:1.0\n---\n"), CalibrationFormat::kOpenCvYaml);
  EXPECT_EQ(DetectCalibrationFormat("{\"cameras\": []}"), CalibrationFormat::kArcoJson);
  EXPECT_EQ(DetectCalibrationFormat("{\"cam0\": {}}"), CalibrationFormat::kSpdJson);
  EXPECT_EQ(DetectCalibrationFormat("hello"), CalibrationFormat::kUnknown);
  EXPECT_EQ(DetectCalibrationFormat(""), CalibrationFormat::kUnknown);
}

TEST(LoadCalibration, ReadsTheRealFilesInEachFormat) {
  auto xml = LoadCalibration(SpdPath("cello_1113_scale_camera.xml"));
  ASSERT_TRUE(xml.ok()) << xml.status().message();
  EXPECT_EQ(xml->format, CalibrationFormat::kMetashapeXml);
  EXPECT_EQ(xml->rig.cameras.size(), 20u);
  auto json = LoadCalibration(SpdPath("cello_1113_scale_camera.json"));
  ASSERT_TRUE(json.ok()) << json.status().message();
  EXPECT_EQ(json->format, CalibrationFormat::kSpdJson);
  EXPECT_EQ(json->rig.units, "metashape");
  ExpectSameRig(xml->rig, json->rig, 1e-9, /*names_kept=*/false);
}

class RoundTrip : public WithTempDir, public ::testing::WithParamInterface<std::string> {};

TEST_P(RoundTrip, ReadWriteReadKeepsTheRig) {
  for (const char* source :
       {"cello_1113_scale_camera.xml", "camera.xml", "cello_1113_pgy_camera.xml"}) {
    auto original = LoadCalibration(SpdPath(source));
    ASSERT_TRUE(original.ok()) << original.status().message();
    const std::string path = Path("rig." + GetParam());
    const bool spd = GetParam() == "spd.json";
    ASSERT_TRUE(SaveCalibration(path,
                                original->rig,
                                spd ? CalibrationFormat::kSpdJson : CalibrationFormat::kUnknown)
                    .ok());
    auto back = LoadCalibration(path);
    ASSERT_TRUE(back.ok()) << back.status().message();
    // SPD JSON has no names (only camN keys); the others keep them exactly.
    ExpectSameRig(original->rig, back->rig, spd ? 1e-12 : 0.0, /*names_kept=*/!spd);
    // Writers are deterministic and reading loses nothing they wrote: writing the
    // re-read rig and reading that back gives the same bytes again. (SPD JSON
    // reorders cameras by key on the first pass, hence two passes.)
    const CalibrationFormat format =
        spd ? CalibrationFormat::kSpdJson : CalibrationFormat::kUnknown;
    const std::string again = Path("again." + GetParam());
    const std::string again2 = Path("again2." + GetParam());
    ASSERT_TRUE(SaveCalibration(again, back->rig, format).ok());
    ASSERT_TRUE(SaveCalibration(again2, LoadCalibration(again)->rig, format).ok());
    EXPECT_TRUE(*ReadFileToString(again) == *ReadFileToString(again2)) << source;
    if (!spd) {
      EXPECT_TRUE(*ReadFileToString(path) == *ReadFileToString(again)) << source;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Writers,
                         RoundTrip,
                         ::testing::Values("yaml", "yml", "xml", "json", "spd.json"),
                         [](const auto& info) {
                           std::string name = info.param;
                           for (char& c : name) c = c == '.' ? '_' : c;
                           return name;
                         });

using SaveCalibrationTest = WithTempDir;

TEST_F(SaveCalibrationTest, NamesWithYamlAndXmlSpecialCharactersRoundTrip) {
  auto cal = LoadCalibration(SpdPath("camera.xml"));
  ASSERT_TRUE(cal.ok());
  Rig rig = cal->rig;
  rig.cameras.resize(5);
  const std::vector<std::string> names = {
      "caméra 1", "a: \"b\" {c} [d] #e", "<x & y>", "カメラ", " 'lead' "};
  for (size_t i = 0; i < names.size(); ++i) rig.cameras[i].name = names[i];
  rig.cameras[1].serial = "0012";
  for (const char* file : {"rig.yaml", "rig.xml", "rig.json"}) {
    ASSERT_TRUE(SaveCalibration(Path(file), rig).ok()) << file;
    auto back = LoadCalibration(Path(file));
    ASSERT_TRUE(back.ok()) << back.status().message();
    ASSERT_EQ(back->rig.cameras.size(), names.size());
    for (size_t i = 0; i < names.size(); ++i) {
      EXPECT_EQ(back->rig.cameras[i].name, names[i]) << file;
      EXPECT_EQ(back->rig.cameras[i].serial, rig.cameras[i].serial) << file;
    }
  }
}

TEST_F(SaveCalibrationTest, RefusesUnknownExtensionAndInvalidRigWithoutLeavingAFile) {
  auto cal = LoadCalibration(SpdPath("camera.xml"));
  ASSERT_TRUE(cal.ok());
  Status s = SaveCalibration(Path("rig.txt"), cal->rig);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("rig.txt"), std::string::npos);
  Rig bad = cal->rig;
  bad.cameras[3].cam_from_world.rotation(0, 0) = 5;
  s = SaveCalibration(Path("rig.yaml"), bad);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("rotation"), std::string::npos) << s.message();
  EXPECT_FALSE(SaveCalibration(Path("rig.xml"), cal->rig, CalibrationFormat::kMetashapeXml).ok());
  EXPECT_TRUE(fs::is_empty(dir_.path()));
}

TEST(CalibrationFormatFromFlag, AcceptsTheDocumentedNames) {
  EXPECT_EQ(*CalibrationFormatFromFlag("yaml"), CalibrationFormat::kOpenCvYaml);
  EXPECT_EQ(*CalibrationFormatFromFlag("spd"), CalibrationFormat::kSpdJson);
  EXPECT_EQ(*CalibrationFormatFromFlag("arco"), CalibrationFormat::kArcoJson);
  EXPECT_EQ(*CalibrationFormatFromFlag("opencv-xml"), CalibrationFormat::kOpenCvXml);
  EXPECT_FALSE(CalibrationFormatFromFlag("metashape").ok());
}

TEST(LoadCalibration, MalformedFilesGiveOneLineErrors) {
  const std::string good_yaml =
      *WriteOpenCvCalibration(LoadCalibration(SpdPath("camera.xml"))->rig, true);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "empty file"},
      {"hello", "not a calibration file"},
      {"%YAML:1.0\n---\ncameras: [ {", "malformed OpenCV file"},
      {"%YAML:1.0\n---\nunits: mm\n", "no 'cameras' sequence"},
      {"%YAML:1.0\n---\ncameras:\n  - name: a\n", "no integer 'image_width'"},
      {"%YAML:1.0\n---\ncameras:\n  - name: a\n    image_width: 10\n    image_height: 10\n"
       "    camera_matrix: 3\n",
       "camera_matrix is not an OpenCV matrix"},
      {good_yaml.substr(0, good_yaml.size() / 2), "OpenCV"},
      {"<?xml version=\"1.0\"?>\n<opencv_storage><cameras>", "malformed OpenCV file"},
  };
  for (const auto& [text, expected] : cases) {
    auto cal = ParseCalibration(text, "bad.yaml");
    ASSERT_FALSE(cal.ok()) << text;
    const std::string& message = cal.status().message();
    EXPECT_EQ(message.rfind("bad.yaml: ", 0), 0u) << message;
    EXPECT_NE(message.find(expected), std::string::npos) << message << "\nexpected: " << expected;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  auto missing = LoadCalibration("/nonexistent/rig.xml");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().message(), "/nonexistent/rig.xml: file not found");
}

}  // namespace
}  // namespace arco::calibration
