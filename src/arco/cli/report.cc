#include "arco/cli/report.h"

#include <cstdio>
#include <sstream>

namespace arco::cli {
namespace {

std::string Format(const char* fmt, double a, double b = 0, double c = 0, double d = 0) {
  char buf[256];
  std::snprintf(buf, sizeof(buf), fmt, a, b, c, d);
  return buf;
}

}  // namespace

std::string FormatRefineSummary(const refine::RefineSummary& s) {
  char buf[512];
  if (s.mode == refine::RefineMode::kVision) {
    std::snprintf(buf,
                  sizeof(buf),
                  "vision: fitted hand on %d of %d frames (no audio)",
                  s.frames_with_hand,
                  s.frames);
    return buf;
  }
  std::snprintf(buf,
                sizeof(buf),
                "%s: %d pressed, %d open string, %d rest, %d uncertain of %d frames; %d notes; "
                "%d corrected, fingertip to contact %.1f -> %.2f mm; %d out of reach; %d limit "
                "violations",
                refine::RefineModeName(s.mode),
                s.pressed,
                s.open_string,
                s.rest,
                s.uncertain,
                s.frames,
                s.usable_notes,
                s.corrected_frames,
                s.mean_tip_distance_vision_mm,
                s.mean_tip_distance_refined_mm,
                s.rejected_out_of_reach,
                s.joint_limit_violations);
  return buf;
}

std::string FormatStageLine(const pipeline::RunSummary& summary,
                            const pipeline::StageTiming& timing) {
  if (timing.name == "triangulate") {
    const SequenceTriangulationSummary& t = summary.triangulate.triangulation;
    char line[256];
    std::snprintf(line,
                  sizeof(line),
                  "%lld of %lld points, median reprojection %.2f px (units %s)",
                  static_cast<long long>(t.triangulated),
                  static_cast<long long>(t.points),
                  t.median_rms_reprojection_px,
                  summary.triangulate.units.c_str());
    if (t.one_view)  // one camera: the depth is placed, not measured
      return std::string(line) +
             Format(", instrument depth +-%.0f mm (median over frames)", t.median_depth_sigma_mm);
    return line;
  }
  if (timing.name == "instrument") {
    const pipeline::InstrumentStageSummary& i = summary.instrument;
    return Format("%.0f of %.0f frames with a pose, median residual %.2f mm",
                  i.frames_with_pose,
                  static_cast<double>(i.frames),
                  i.median_rms_residual_mm) +
           Format(", scale %.4g units/mm, poses smoothed over sigma %.0f frames",
                  i.world_units_per_mm,
                  i.smoothing_sigma_frames);
  }
  if (timing.name == "hands") {
    const pipeline::HandStageSummary& h = summary.hands;
    return Format(
        "left hand fitted on %.0f of %.0f frames, reprojection median %.2f px (RMS %.2f px, "
        "outliers included)",
        h.frames_fitted,
        static_cast<double>(h.frames),
        h.median_residual_px,
        h.median_rms_residual_px);
  }
  if (timing.name == "pitch") {
    const pipeline::PitchStageSummary& p = summary.pitch;
    return Format("%.1f s of audio, %.0f%% voiced, %.0f notes",
                  p.duration_s,
                  100.0 * p.voiced_fraction,
                  static_cast<double>(p.notes));
  }
  if (timing.name == "refine") {
    std::string methods;
    for (const refine::RefineSummary& m : summary.methods)
      methods += std::string(methods.empty() ? "" : ", ") + refine::RefineModeName(m.mode);
    return "wrote " + methods;
  }
  return "";
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

}  // namespace arco::cli
