#include "arco/cli/triangulate.h"

#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>

#include "arco/calibration/calibration_file.h"
#include "arco/mocap/triangulate_sequence.h"
#include "arco/util/file_io.h"

namespace arco::cli {
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
    return Status::Error("need at least two --view CAMERA=LABELME.json (got " +
                         std::to_string(o.views.size()) + ")");
  }
  ARCO_ASSIGN_OR_RETURN(Calibration calibration, LoadCalibration(o.calibration));
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

std::string FormatLabelViewsReport(const Json& r) {
  std::ostringstream s;
  char line[256];
  std::snprintf(line,
                sizeof(line),
                "%-14s %10s %10s %10s  %7s  %s\n",
                "point",
                "x",
                "y",
                "z",
                "rms px",
                "inlier views");
  s << line;
  for (const Json& p : r["points"]) {
    std::string views;
    for (const Json& v : p["inlier_views"])
      views += (views.empty() ? "" : ",") + v.get<std::string>();
    std::snprintf(line,
                  sizeof(line),
                  "%-14s %10.4f %10.4f %10.4f  %7.2f  %s\n",
                  p["name"].get<std::string>().c_str(),
                  p["xyz"][0].get<double>(),
                  p["xyz"][1].get<double>(),
                  p["xyz"][2].get<double>(),
                  p["rms_reprojection_px"].get<double>(),
                  views.c_str());
    s << line;
  }
  for (const Json& n : r["not_triangulated"]) {
    s << n.get<std::string>() << ": seen in fewer than two agreeing views\n";
  }
  std::snprintf(line,
                sizeof(line),
                "overall reprojection RMS: %.2f px (%s, units: %s)\n",
                r["rms_reprojection_px"].get<double>(),
                r["distortion_modelled"].get<bool>() ? "distortion modelled" : "distortion ignored",
                r["units"].get<std::string>().c_str());
  s << line;
  if (r.contains("lengths")) {
    const Json& l = r["lengths"];
    std::snprintf(
        line,
        sizeof(line),
        "string sides: nut_l-bridge_l %.4f, nut_r-bridge_r %.4f units (differ by %.2f%%)\n",
        l["nut_l-bridge_l"].get<double>(),
        l["nut_r-bridge_r"].get<double>(),
        l["difference_percent"].get<double>());
    s << line;
    if (l.contains("mm_per_unit")) {
      std::snprintf(line,
                    sizeof(line),
                    "scaled so the mean string side is %.0f mm: nut_l-bridge_l %.1f mm, "
                    "nut_r-bridge_r %.1f mm, nut width %.1f mm, bridge width %.1f mm\n",
                    l["reference_string_length_mm"].get<double>(),
                    l["nut_l-bridge_l_mm"].get<double>(),
                    l["nut_r-bridge_r_mm"].get<double>(),
                    l["nut_l-nut_r_mm"].get<double>(),
                    l["bridge_l-bridge_r_mm"].get<double>());
      s << line;
    }
  }
  return s.str();
}

StatusOr<CaptureRunSummary> TriangulateCapture(const CaptureOptions& o,
                                               const std::function<void(int64_t)>& progress,
                                               const std::function<void(int64_t)>& on_start) {
  ARCO_RETURN_IF_ERROR(o.triangulation.Validate());
  ARCO_ASSIGN_OR_RETURN(CaptureManifest manifest, ReadCaptureManifest(o.capture_dir));
  const std::string manifest_path = JoinPath(o.capture_dir, kCaptureManifestName);
  ARCO_ASSIGN_OR_RETURN(KeypointLayout layout, [&]() -> StatusOr<KeypointLayout> {
    if (manifest.keypoints2d.empty()) {
      return Status::Error(manifest_path + ": no \"keypoints2d\" entry to triangulate");
    }
    auto l = manifest.Layout();
    if (!l.ok()) return l.status().WithContext(manifest_path);
    return l;
  }());
  // Filters refer to groups of the layout; check them before any work.
  std::vector<std::pair<const std::vector<int>*, TemporalFilterOptions>> filters;
  for (const auto& [group, filter] : o.filters) {
    const std::vector<int>* indices = layout.Group(group);
    if (!indices) {
      std::string known;
      for (const auto& g : layout.groups) known += (known.empty() ? "" : ", ") + g.name;
      return Status::Error("filter group \"" + group + "\" is not in layout " + layout.name +
                           " (groups: " + known + ")");
    }
    const Status valid = filter.Validate(manifest.fps);
    if (!valid.ok()) {
      return Status::Error("filter " + group + "=" + FilterSpecToString(filter) + " at " +
                           std::to_string(manifest.fps) + " fps (" + manifest_path +
                           "): " + valid.message());
    }
    filters.emplace_back(indices, filter);
  }
  const std::string calibration_path = ResolveCapturePath(o.capture_dir, manifest.calibration);
  ARCO_ASSIGN_OR_RETURN(Calibration calibration, LoadCalibration(calibration_path));
  std::vector<int> view_to_camera;
  for (const auto& cam : manifest.cameras) {
    int c = calibration.rig.FindCamera(cam.name);
    if (c < 0 && !cam.serial.empty()) c = calibration.rig.FindCamera(cam.serial);
    if (c < 0) {
      return Status::Error(manifest_path + ": camera \"" + cam.name + "\" is not in " +
                           calibration_path);
    }
    view_to_camera.push_back(c);
  }
  ARCO_ASSIGN_OR_RETURN(NpyArray<double> keypoints,
                        ReadCaptureKeypoints2d(o.capture_dir, manifest));
  if (on_start) on_start(manifest.frame_count);
  ARCO_ASSIGN_OR_RETURN(
      SequenceTriangulation raw,
      TriangulateSequence(calibration.rig,
                          view_to_camera,
                          keypoints,
                          o.triangulation,
                          progress,
                          ResolveCapturePath(o.capture_dir, manifest.keypoints2d)));
  NpyArray<double> filtered = raw.points3d;
  Json filter_json = Json::array();
  for (size_t i = 0; i < filters.size(); ++i) {
    FilterPoints(filters[i].second, manifest.fps, *filters[i].first, &filtered);
    filter_json.push_back({{"group", o.filters[i].first},
                           {"filter", FilterSpecToString(o.filters[i].second)},
                           {"max_gap_frames", o.filters[i].second.max_gap_frames}});
  }
  const TriangulationOptions& t = o.triangulation.point;
  TriangulationStageInfo info;
  info.capture_dir = o.capture_dir;
  info.units = calibration.rig.units;
  info.summary = Summarize(raw);
  info.options = {{"min_score", t.min_score},
                  {"max_reprojection_px", t.max_reprojection_px},
                  {"max_ransac_trials", t.max_ransac_trials},
                  {"ransac_confidence", t.ransac_confidence},
                  {"seed", t.seed},
                  {"weight_by_score", t.weight_by_score},
                  {"refine", t.refine},
                  {"robust_loss_scale_px", t.robust_loss_scale_px},
                  {"max_refine_iterations", t.max_refine_iterations},
                  {"filters", filter_json}};
  ARCO_RETURN_IF_ERROR(
      WriteTriangulationResult(o.result_dir, manifest, layout, raw, filtered, info));
  CaptureRunSummary summary;
  summary.triangulation = info.summary;
  summary.units = info.units;
  summary.views = static_cast<int64_t>(view_to_camera.size());
  summary.keypoints = layout.size();
  return summary;
}

}  // namespace arco::cli
