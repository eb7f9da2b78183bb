#include "arco/calibration/calibration_file.h"

#include <algorithm>
#include <filesystem>

#include "arco/util/file_io.h"
#include "arco/util/json_io.h"

namespace arco::calibration {
namespace {

std::string LowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(
      ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

// The text after a UTF-8 byte order mark, leading whitespace and an XML declaration.
std::string_view Start(const std::string& text) {
  std::string_view s(text);
  if (s.substr(0, 3) == "\xEF\xBB\xBF") s.remove_prefix(3);
  auto skip_space = [&] {
    while (!s.empty() && (s[0] == ' ' || s[0] == '\t' || s[0] == '\n' || s[0] == '\r')) {
      s.remove_prefix(1);
    }
  };
  skip_space();
  while (s.substr(0, 2) == "<?" || s.substr(0, 4) == "<!--") {
    const size_t end = s.find(s[1] == '?' ? "?>" : "-->");
    if (end == std::string_view::npos) break;
    s.remove_prefix(end + (s[1] == '?' ? 2 : 3));
    skip_space();
  }
  return s;
}

}  // namespace

CalibrationFormat DetectCalibrationFormat(const std::string& text) {
  const std::string_view s = Start(text);
  if (s.substr(0, 15) == "<opencv_storage") return CalibrationFormat::kOpenCvXml;
  if (s.substr(0, 1) == "<") return CalibrationFormat::kMetashapeXml;
  if (s.substr(0, 5) == "%YAML") return CalibrationFormat::kOpenCvYaml;
  if (s.substr(0, 1) == "{") {
    // arco JSON has a top-level "cameras" array; SPD JSON is keyed by camera name.
    auto json = ParseJsonLenient(text, "");
    if (json.ok() && json->is_object() && json->contains("cameras")) {
      return CalibrationFormat::kArcoJson;
    }
    return CalibrationFormat::kSpdJson;
  }
  return CalibrationFormat::kUnknown;
}

StatusOr<Calibration> ParseCalibration(const std::string& text, const std::string& source) {
  switch (DetectCalibrationFormat(text)) {
    case CalibrationFormat::kMetashapeXml:
      return ParseMetashapeXml(text, source);
    case CalibrationFormat::kSpdJson:
      return ParseSpdJson(text, source);
    case CalibrationFormat::kArcoJson:
      return ParseArcoJson(text, source);
    case CalibrationFormat::kOpenCvYaml:
    case CalibrationFormat::kOpenCvXml:
      return ParseOpenCvCalibration(text, source);
    case CalibrationFormat::kUnknown:
      break;
  }
  if (text.empty()) return Status::Error(source + ": empty file");
  return Status::Error(source +
                       ": not a calibration file (expected Metashape XML, SPD/arco JSON or "
                       "OpenCV YAML/XML)");
}

StatusOr<Calibration> LoadCalibration(const std::string& path) {
  ARCO_ASSIGN_OR_RETURN(std::string text, ReadFileToString(path));
  return ParseCalibration(text, path);
}

StatusOr<CalibrationFormat> CalibrationFormatFromFlag(const std::string& flag) {
  if (flag == "yaml" || flag == "opencv-yaml") return CalibrationFormat::kOpenCvYaml;
  if (flag == "opencv-xml") return CalibrationFormat::kOpenCvXml;
  if (flag == "spd" || flag == "spd-json") return CalibrationFormat::kSpdJson;
  if (flag == "arco" || flag == "arco-json") return CalibrationFormat::kArcoJson;
  return Status::Error("unknown calibration format '" + flag +
                       "' (expected yaml, opencv-xml, spd or arco)");
}

Status SaveCalibration(const std::string& path, const Rig& rig, CalibrationFormat format) {
  if (format == CalibrationFormat::kUnknown) {
    const std::string ext = LowerExtension(path);
    if (ext == ".yaml" || ext == ".yml") {
      format = CalibrationFormat::kOpenCvYaml;
    } else if (ext == ".xml") {
      format = CalibrationFormat::kOpenCvXml;
    } else if (ext == ".json") {
      format = CalibrationFormat::kArcoJson;
    } else {
      return Status::Error(path + ": cannot tell the format from the extension '" + ext +
                           "' (use .yaml, .xml, .json or give a format)");
    }
  }
  StatusOr<std::string> text = Status::Error("Metashape XML cannot be written");
  switch (format) {
    case CalibrationFormat::kOpenCvYaml:
    case CalibrationFormat::kOpenCvXml:
      text = WriteOpenCvCalibration(rig, format == CalibrationFormat::kOpenCvYaml);
      break;
    case CalibrationFormat::kSpdJson:
      text = WriteSpdJson(rig);
      break;
    case CalibrationFormat::kArcoJson:
      text = WriteArcoJson(rig);
      break;
    default:
      break;
  }
  if (!text.ok()) return text.status().WithContext(path);
  return AtomicWriteFile(path, *text);
}

}  // namespace arco::calibration
