// `arco export`: a result folder's 3D points in the formats other tools read
// (docs/export.md). Results are read through pipeline::ResultFolder (the folder's one
// owner); each format has one writer here, returning the file's bytes.
//
// Conventions, for every format: the points are a method's points3d.npy (arco, paper or
// vision: mm, arco's world axes, the SPD contact layout), every point named by arco's
// keypoint names (docs/formats.md); frame k of the export is the result's frame
// frame_first + k, at time k / fps. Missing points (NaN) are gaps as each format expects:
// empty CSV/TRC fields, C3D residual -1, a hidden glTF marker (scale 0), a held BVH pose.
// Lengths: mm in CSV, TRC, C3D and BVH; metres in glTF (the glTF 2.0 unit).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "arco/util/npy.h"
#include "arco/util/status.h"

namespace arco::exporter {

enum class ExportFormat { kCsv, kTrc, kC3d, kGltf, kBvh };

// "csv", "trc", "c3d", "gltf" (also "glb"), "bvh"; an error listing them otherwise.
StatusOr<ExportFormat> ParseExportFormat(const std::string& name);
const char* ExportFormatName(ExportFormat format);
// "arco", "paper", "vision": the method folders of a result.
const std::vector<std::string>& ExportMethodNames();

struct ExportOptions {
  std::string result_dir;       // an `arco run` result folder
  std::string format = "csv";   // ParseExportFormat
  std::string method = "arco";  // ExportMethodNames
  // The file the user names, checked by Validate (CheckExportExtension); empty: not
  // checked (the viewer and overlays read the data without writing a file).
  std::string output;
  Status Validate() const;
};

// The one check of an output's name against the format: its extension must be the
// format's (.csv, .trc, .c3d, .glb, .bvh; any case), so BVH text never lands in a .glb.
Status CheckExportExtension(ExportFormat format, const std::string& output);

// Coordinates every format can hold: finite (NaN is a gap) and within this many mm of the
// origin (1000 km; C3D and glTF store float32, which turns 1e300 into inf).
inline constexpr double kMaxExportCoordinateMm = 1e9;

// What the exporters read: one method's points with their names and timing.
struct ExportData {
  std::string method;
  std::string instrument;  // result.json "instrument" ("" when absent)
  std::vector<std::string> keypoint_names;
  NpyArray<double> points_mm;  // (F, P, 3), NaN where missing
  double fps = 30;
  int64_t frame_first = 1;
  // The instrument's strings, nut and bridge per frame: (F, S, 2, 3) mm; empty when the
  // result has no instrument stage.
  NpyArray<double> strings_mm;
  // The triangulation's evidence for each point (the same-named point of
  // triangulation/): RMS reprojection error (px) and inlier views, (F, P); NaN and 0
  // where the triangulation has no such point or did not triangulate it. Empty when the
  // result has no triangulation quality files.
  NpyArray<double> reprojection_px;
  NpyArray<int32_t> views;

  int64_t frames() const { return points_mm.shape.empty() ? 0 : points_mm.shape[0]; }
  int points() const { return keypoint_names.size(); }
  Eigen::Vector3d At(int64_t frame, int point) const {
    return Eigen::Vector3d(points_mm.at(frame, point, 0),
                           points_mm.at(frame, point, 1),
                           points_mm.at(frame, point, 2));
  }
  int Find(const std::string& name) const;  // -1 when absent
};

// Errors (naming the file): no result.json, no such method in the result, a points3d.npy
// whose shape disagrees with the names, a coordinate that is infinite or beyond
// kMaxExportCoordinateMm (naming the frame and keypoint).
StatusOr<ExportData> LoadExportData(const ExportOptions& options);

// The writers: the file's contents. CSV columns: frame, time_s, keypoint, x_mm, y_mm, z_mm,
// present (0: a gap, x/y/z empty), reprojection_px and views (the triangulation's evidence
// for the point, empty when none).
std::string CsvText(const ExportData& data);
std::string TrcText(const ExportData& data, const std::string& file_name);
// C3D (Motion Lab Systems' format, Intel floats, one parameter block set): POINT:LABELS are
// the keypoint names, UNITS "mm", SCALE -1 (float data), RATE fps. Errors: more frames or
// points than C3D's 16-bit header fields hold.
StatusOr<std::string> C3dBytes(const ExportData& data);
// glTF 2.0 binary: nodes named by keypoint (translation per frame), the strings and bow
// as line meshes, all in metres.
std::string GlbBytes(const ExportData& data);

// BVH: one skeleton (body, both hands with every finger joint), bone lengths the median
// lengths of the result, per-frame rotations fitted to the points.
struct BvhJointResidual {
  std::string name;
  double median_mm = 0;  // |FK position - points3d|, over frames where the point exists
  double max_mm = 0;
  int frames = 0;
};
struct BvhExport {
  std::string text;
  std::vector<BvhJointResidual> residuals;  // the joints that are keypoints
  // Medians over all joint-frames of the body, the left hand and the right hand.
  double body_median_mm = 0, left_hand_median_mm = 0, right_hand_median_mm = 0;
};
StatusOr<BvhExport> ExportBvh(const ExportData& data);

struct ExportSummary {
  ExportFormat format = ExportFormat::kCsv;
  int64_t frames = 0;
  int keypoints = 0;
  int64_t bytes = 0;
  std::vector<BvhJointResidual> bvh_residuals;  // BVH only
  double bvh_body_median_mm = 0, bvh_left_hand_median_mm = 0, bvh_right_hand_median_mm = 0;
};

// Loads the result and writes the export to `path` (a caller wanting an atomic output
// passes an OutputSet temporary); `display_name` is the file name some formats record.
StatusOr<ExportSummary> ExportResult(const ExportOptions& options,
                                     const std::string& path,
                                     const std::string& display_name);

}  // namespace arco::exporter
