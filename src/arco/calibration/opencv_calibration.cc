// OpenCV cv::FileStorage (YAML or XML) calibration <-> Rig; layout in
// calibration_file.h. Values are arco's (OpenCV's) convention, so no conversion.
#include <opencv2/core.hpp>

#include "arco/calibration/calibration_file.h"

namespace arco::calibration {
namespace {

std::string OneLine(std::string s) {
  for (char& c : s) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return s;
}

// A matrix node as doubles, row-major; an error when absent or not a matrix.
Status ReadMatrix(const cv::FileNode& node,
                  const std::string& what,
                  int rows,
                  int cols,
                  std::vector<double>* out) {
  if (node.empty() || node.isNone()) return Status::Error(what + " is missing");
  if (!node.isMap()) return Status::Error(what + " is not an OpenCV matrix");
  cv::Mat m;
  node >> m;
  if (m.empty() || m.channels() != 1) return Status::Error(what + " is not an OpenCV matrix");
  m.convertTo(m, CV_64F);
  const bool shape_ok = (m.rows == rows && m.cols == cols) ||
                        (rows == 1 && m.cols == 1 && m.rows == cols) ||
                        (cols == 1 && m.rows == 1 && m.cols == rows);
  if (!shape_ok) {
    return Status::Error(what + " is " + std::to_string(m.rows) + "x" + std::to_string(m.cols) +
                         ", expected " + std::to_string(rows) + "x" + std::to_string(cols));
  }
  out->assign(m.begin<double>(), m.end<double>());
  return Status::Ok();
}

StatusOr<Camera> ReadCamera(const cv::FileNode& n, size_t index) {
  std::string who = "camera " + std::to_string(index);
  if (!n.isMap()) return Status::Error(who + " is not a map");
  Camera cam;
  if (!n["name"].isString()) return Status::Error(who + " has no string 'name'");
  cam.name = static_cast<std::string>(n["name"]);
  who = "camera '" + cam.name + "'";
  if (!n["serial"].empty()) {
    if (!n["serial"].isString()) return Status::Error(who + " 'serial' is not a string");
    cam.serial = static_cast<std::string>(n["serial"]);
  }
  for (const char* key : {"image_width", "image_height"}) {
    if (!n[key].isInt()) return Status::Error(who + " has no integer '" + key + "'");
    (std::string(key) == "image_width" ? cam.width : cam.height) = static_cast<int>(n[key]);
  }
  std::vector<double> k, d, r, t;
  ARCO_RETURN_IF_ERROR(ReadMatrix(n["camera_matrix"], who + " camera_matrix", 3, 3, &k));
  ARCO_RETURN_IF_ERROR(ReadMatrix(n["rotation"], who + " rotation", 3, 3, &r));
  ARCO_RETURN_IF_ERROR(ReadMatrix(n["translation"], who + " translation", 3, 1, &t));
  if (!n["distortion_coefficients"].empty()) {
    cv::Mat m;
    const cv::FileNode dn = n["distortion_coefficients"];
    if (!dn.isMap()) return Status::Error(who + " distortion_coefficients is not a matrix");
    dn >> m;
    if (m.channels() != 1 || (m.rows != 1 && m.cols != 1)) {
      return Status::Error(who + " distortion_coefficients is not a vector");
    }
    m.convertTo(m, CV_64F);
    d.assign(m.begin<double>(), m.end<double>());
    // OpenCV order k1 k2 p1 p2 [k3 [k4 k5 k6 ...]]; arco models up to k3.
    if (d.size() < 4)
      return Status::Error(who + " distortion_coefficients has fewer than 4 values");
    for (size_t i = 5; i < d.size(); ++i) {
      if (d[i] != 0) {
        return Status::Error(who + " uses distortion terms beyond k3, which arco does not model");
      }
    }
    cam.distortion = {d[0], d[1], d.size() > 4 ? d[4] : 0.0, d[2], d[3]};
  }
  if (k[3] != 0 || k[6] != 0 || k[7] != 0 || k[8] != 1) {
    return Status::Error(who + " camera_matrix is not an intrinsic matrix");
  }
  cam.fx = k[0];
  cam.skew = k[1];
  cam.cx = k[2];
  cam.fy = k[4];
  cam.cy = k[5];
  cam.cam_from_world.rotation = Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(r.data());
  cam.cam_from_world.translation = Eigen::Vector3d(t[0], t[1], t[2]);
  ARCO_RETURN_IF_ERROR(ValidateCamera(cam));
  return cam;
}

StatusOr<Calibration> ParseStorage(const cv::FileStorage& fs) {
  Calibration result;
  const cv::FileNode format = fs["format"];
  if (!format.empty() && (!format.isString() || format.string() != "arco-calibration")) {
    return Status::Error("'format' is not \"arco-calibration\"");
  }
  if (!fs["units"].empty()) {
    if (!fs["units"].isString()) return Status::Error("'units' is not a string");
    result.rig.units = fs["units"].string();
  }
  const cv::FileNode cameras = fs["cameras"];
  if (!cameras.isSeq()) return Status::Error("no 'cameras' sequence");
  for (size_t i = 0; i < cameras.size(); ++i) {
    ARCO_ASSIGN_OR_RETURN(Camera cam, ReadCamera(cameras[static_cast<int>(i)], i));
    result.rig.cameras.push_back(std::move(cam));
  }
  ARCO_RETURN_IF_ERROR(ValidateRig(result.rig));
  return result;
}

}  // namespace

StatusOr<Calibration> ParseOpenCvCalibration(const std::string& text, const std::string& source) {
  if (text.empty()) return Status::Error(source + ": empty file");
  try {
    cv::FileStorage fs(text, cv::FileStorage::READ | cv::FileStorage::MEMORY);
    if (!fs.isOpened()) return Status::Error(source + ": not an OpenCV YAML/XML file");
    auto result = ParseStorage(fs);
    if (!result.ok()) return result.status().WithContext(source);
    result->format = fs.getFormat() == cv::FileStorage::FORMAT_XML ? CalibrationFormat::kOpenCvXml
                                                                   : CalibrationFormat::kOpenCvYaml;
    return result;
  } catch (const cv::Exception& e) {
    return Status::Error(source + ": malformed OpenCV file (" + OneLine(e.err) + ")");
  }
}

StatusOr<std::string> WriteOpenCvCalibration(const Rig& rig, bool yaml) {
  ARCO_RETURN_IF_ERROR(ValidateRig(rig));
  try {
    cv::FileStorage fs(yaml ? ".yml" : ".xml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
    fs << "format"
       << "arco-calibration";
    fs << "units" << rig.units;
    fs << "cameras"
       << "[";
    for (const Camera& cam : rig.cameras) {
      cv::Mat k(3, 3, CV_64F), r(3, 3, CV_64F), t(3, 1, CV_64F);
      const Eigen::Matrix3d kk = cam.K();
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
          k.at<double>(i, j) = kk(i, j);
          r.at<double>(i, j) = cam.cam_from_world.rotation(i, j);
        }
        t.at<double>(i, 0) = cam.cam_from_world.translation[i];
      }
      const Distortion& d = cam.distortion;
      cv::Mat dist = (cv::Mat_<double>(1, 5) << d.k1, d.k2, d.p1, d.p2, d.k3);
      fs << "{";
      fs << "name" << cam.name << "serial" << cam.serial;
      fs << "image_width" << cam.width << "image_height" << cam.height;
      fs << "camera_matrix" << k << "distortion_coefficients" << dist;
      fs << "rotation" << r << "translation" << t;
      fs << "}";
    }
    fs << "]";
    return fs.releaseAndGetString();
  } catch (const cv::Exception& e) {
    return Status::Error("cannot write OpenCV calibration (" + OneLine(e.err) + ")");
  }
}

}  // namespace arco::calibration
