#include "arco/capture/label_views.h"

#include <cmath>
#include <map>
#include <set>

#include "arco/calibration/calibration_file.h"
#include "arco/util/file_io.h"

namespace arco::capture {
namespace {

struct LoadedView {
  std::string id;    // as the user named the camera
  std::string path;  // labelme file
  int camera = -1;   // rig index
  LabelmeAnnotation labels;
};

Json Vec3(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

}  // namespace

StatusOr<Json> TriangulateLabelViews(const LabelViewsOptions& o) {
  if (o.views.size() < 2) {
    return Status::Error("views: need at least two (camera, labelme file) views (got " +
                         std::to_string(o.views.size()) + ")");
  }
  ARCO_ASSIGN_OR_RETURN(Calibration calibration, calibration::LoadCalibration(o.calibration));
  Rig rig = calibration.rig;
  if (o.ignore_distortion) {
    for (Camera& c : rig.cameras) c.distortion = Distortion();
  }
  std::vector<LoadedView> views;
  std::set<int> used;
  for (const auto& [id, path] : o.views) {
    LoadedView v;
    v.id = id;
    v.path = path;
    v.camera = rig.FindCamera(id);
    if (v.camera < 0) {
      return Status::Error(path + ": camera \"" + id + "\" is not in " + o.calibration);
    }
    if (!used.insert(v.camera).second) {
      return Status::Error(path + ": camera \"" + id + "\" (" + rig.cameras[v.camera].name +
                           ") is given twice");
    }
    ARCO_ASSIGN_OR_RETURN(v.labels, ReadLabelme(path, o.label_origin));
    const Camera& cam = rig.cameras[v.camera];
    if ((v.labels.image_width && v.labels.image_width != cam.width) ||
        (v.labels.image_height && v.labels.image_height != cam.height)) {
      return Status::Error(path + ": image is " + std::to_string(v.labels.image_width) + "x" +
                           std::to_string(v.labels.image_height) + " but camera \"" + id +
                           "\" in " + o.calibration + " is " + std::to_string(cam.width) + "x" +
                           std::to_string(cam.height));
    }
    views.push_back(std::move(v));
  }
  // Labels in order of first appearance (views in command-line order).
  std::vector<std::string> names;
  std::set<std::string> seen;
  for (const auto& v : views) {
    for (const auto& p : v.labels.points) {
      if (seen.insert(p.label).second) names.push_back(p.label);
    }
  }
  const Triangulator triangulator(rig, o.triangulation);
  Json points = Json::array();
  Json missing = Json::array();
  std::map<std::string, Eigen::Vector3d> xyz;
  double sum_sq = 0;
  int64_t observations = 0;
  for (const std::string& name : names) {
    std::vector<PointObservation> obs;
    for (const auto& v : views) {
      const int i = v.labels.Find(name);
      if (i >= 0) obs.push_back({v.camera, v.labels.points[i].pixel, 1.0});
    }
    const auto r = triangulator.Triangulate(obs);
    if (!r) {
      missing.push_back(name);
      continue;
    }
    Json inliers = Json::array();
    Json errors = Json::object();
    for (const auto& v : views) {
      const int i = v.labels.Find(name);
      if (i < 0) continue;
      const double e =
          ReprojectionErrorPx(rig.cameras[v.camera], r->point_in_world, v.labels.points[i].pixel);
      errors[v.id] = JsonFromDouble(e);
      for (int c : r->inlier_cameras) {
        if (c == v.camera) {
          inliers.push_back(v.id);
          sum_sq += e * e;
          ++observations;
        }
      }
    }
    xyz[name] = r->point_in_world;
    points.push_back({{"name", name},
                      {"xyz", Vec3(r->point_in_world)},
                      {"inlier_views", inliers},
                      {"rms_reprojection_px", r->rms_reprojection_px},
                      {"num_views", r->num_views},
                      {"reprojection_px", errors}});
  }
  if (points.empty()) {
    return Status::Error("no label is seen in two or more views that agree (views: " +
                         views.front().path + ", ...)");
  }
  Json out;
  out["units"] = rig.units;
  out["calibration"] = o.calibration;
  out["distortion_modelled"] = !o.ignore_distortion;
  out["rms_reprojection_px"] = std::sqrt(sum_sq / static_cast<double>(observations));
  out["points"] = points;
  out["not_triangulated"] = missing;
  Json views_json = Json::array();
  for (const auto& v : views) {
    views_json.push_back({{"camera", v.id},
                          {"name", rig.cameras[v.camera].name},
                          {"serial", rig.cameras[v.camera].serial},
                          {"labels", v.path}});
  }
  out["views"] = views_json;
  // String sides: the two nut-to-bridge edges of the fingerboard (DOMAIN.md section 2).
  if (xyz.count("nut_l") && xyz.count("bridge_l") && xyz.count("nut_r") && xyz.count("bridge_r")) {
    const double left = (xyz["nut_l"] - xyz["bridge_l"]).norm();
    const double right = (xyz["nut_r"] - xyz["bridge_r"]).norm();
    const double mean = 0.5 * (left + right);
    Json lengths = {{"nut_l-bridge_l", left},
                    {"nut_r-bridge_r", right},
                    {"difference_percent", 100.0 * std::abs(left - right) / mean}};
    if (o.reference_string_length_mm > 0) {
      const double mm_per_unit = o.reference_string_length_mm / mean;
      lengths["mm_per_unit"] = mm_per_unit;
      lengths["reference_string_length_mm"] = o.reference_string_length_mm;
      lengths["nut_l-bridge_l_mm"] = left * mm_per_unit;
      lengths["nut_r-bridge_r_mm"] = right * mm_per_unit;
      if (xyz.count("nut_l") && xyz.count("nut_r")) {
        lengths["nut_l-nut_r_mm"] = (xyz["nut_l"] - xyz["nut_r"]).norm() * mm_per_unit;
      }
      lengths["bridge_l-bridge_r_mm"] = (xyz["bridge_l"] - xyz["bridge_r"]).norm() * mm_per_unit;
    }
    out["lengths"] = lengths;
  }
  return out;
}

}  // namespace arco::capture
