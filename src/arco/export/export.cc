#include "arco/export/export.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>

#include "arco/pipeline/result_folder.h"
#include "arco/util/file_io.h"

namespace arco::exporter {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct FormatName {
  ExportFormat format;
  const char* name;
};
constexpr FormatName kFormats[] = {{ExportFormat::kCsv, "csv"},
                                   {ExportFormat::kTrc, "trc"},
                                   {ExportFormat::kC3d, "c3d"},
                                   {ExportFormat::kGltf, "gltf"},
                                   {ExportFormat::kBvh, "bvh"}};

// Shortest text that reads back within 1e-6 mm.
void AppendNumber(std::string& out, double v) {
  char buf[64];
  const int n = std::snprintf(buf, sizeof(buf), "%.6f", v);
  out.append(buf, n);
}

}  // namespace

StatusOr<ExportFormat> ParseExportFormat(const std::string& name) {
  if (name == "glb") return ExportFormat::kGltf;
  for (const auto& f : kFormats) {
    if (name == f.name) return f.format;
  }
  return Status::Error("unknown export format '" + name + "' (csv, trc, c3d, gltf, bvh)");
}

const char* ExportFormatName(ExportFormat format) {
  for (const auto& f : kFormats) {
    if (f.format == format) return f.name;
  }
  return "?";
}

const std::vector<std::string>& ExportMethodNames() {
  static const std::vector<std::string> names = {"arco", "paper", "vision"};
  return names;
}

Status ExportOptions::Validate() const {
  if (result_dir.empty()) return Status::Error("result_dir is empty");
  if (!ParseExportFormat(format).ok()) {
    return Status::Error("format: '" + format + "' is not csv, trc, c3d, gltf (glb) or bvh");
  }
  if (!output.empty())
    ARCO_RETURN_IF_ERROR(CheckExportExtension(*ParseExportFormat(format), output));
  bool known = false;
  for (const auto& m : ExportMethodNames()) known = known || m == method;
  if (!known) {
    return Status::Error("method: '" + method + "' is not arco, paper or vision");
  }
  return Status::Ok();
}

Status CheckExportExtension(ExportFormat format, const std::string& output) {
  const std::string wanted = format == ExportFormat::kGltf ? "glb" : ExportFormatName(format);
  const size_t slash = output.find_last_of('/');
  const size_t dot = output.find_last_of('.');
  std::string extension = dot == std::string::npos || (slash != std::string::npos && dot < slash)
                              ? ""
                              : output.substr(dot + 1);
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension == wanted) return Status::Ok();
  return Status::Error(output + ": a " + ExportFormatName(format) + " export is named ." + wanted +
                       ", not " +
                       (extension.empty() ? std::string("without an extension") : "." + extension) +
                       " (rename the output, or choose the format its extension names)");
}

namespace {

// The one check of the coordinates the writers receive (see kMaxExportCoordinateMm):
// `values` (..., 3) mm, NaN allowed; `where(i)` names the point of flat index i.
Status CheckCoordinates(const std::vector<double>& values,
                        const std::string& path,
                        const std::function<std::string(int64_t)>& where) {
  for (size_t i = 0; i < values.size(); ++i) {
    const double v = values[i];
    if (std::isnan(v) || std::abs(v) <= kMaxExportCoordinateMm) continue;
    char text[64];
    std::snprintf(text, sizeof(text), "%g", v);
    return Status::Error(path + ": " + where(static_cast<int64_t>(i / 3)) + ": coordinate " + text +
                         " mm is not finite or beyond 1e9 mm; no export can hold it");
  }
  return Status::Ok();
}

}  // namespace

int ExportData::Find(const std::string& name) const {
  for (size_t i = 0; i < keypoint_names.size(); ++i) {
    if (keypoint_names[i] == name) return static_cast<int>(i);
  }
  return -1;
}

StatusOr<ExportData> LoadExportData(const ExportOptions& options) {
  const pipeline::ResultFolder folder(options.result_dir);
  ARCO_ASSIGN_OR_RETURN(const pipeline::ResultHeader header, folder.ReadHeader());
  ARCO_ASSIGN_OR_RETURN(const std::vector<pipeline::PointStage> stages, folder.PointStages());
  const pipeline::PointStage* stage = nullptr;
  for (const auto& s : stages) {
    if (s.name == options.method) stage = &s;
  }
  if (stage == nullptr) {
    std::string have;
    for (const auto& s : stages) {
      if (s.name == "triangulation") continue;
      have += (have.empty() ? "" : ", ") + s.name;
    }
    return Status::Error(folder.ManifestPath() + ": the result has no '" + options.method +
                         "' points (stages with points: " + (have.empty() ? "none" : have) +
                         "; arco refine writes them)");
  }
  ExportData data;
  data.method = options.method;
  data.fps = header.fps;
  data.frame_first = header.frame_first;
  data.keypoint_names =
      stage->keypoint_names.empty() ? header.keypoint_names : stage->keypoint_names;
  ARCO_ASSIGN_OR_RETURN(data.points_mm, folder.ReadPoints3d(options.method));
  const auto& shape = data.points_mm.shape;
  if (shape.size() != 3 || shape[0] < 1 || shape[2] != 3 ||
      shape[1] != static_cast<int64_t>(data.keypoint_names.size())) {
    return Status::Error(stage->points3d_path + ": shape is not (frames >= 1, " +
                         std::to_string(data.keypoint_names.size()) + ", 3)");
  }
  ARCO_RETURN_IF_ERROR(CheckCoordinates(data.points_mm.data, stage->points3d_path, [&](int64_t i) {
    return "frame " + std::to_string(data.frame_first + i / shape[1]) + " keypoint '" +
           data.keypoint_names[i % shape[1]] + "'";
  }));
  // The triangulation's quality, matched by name (absent in results of older versions).
  auto quality = folder.ReadTriangulationQuality();
  if (quality.ok()) {
    const auto& rms = quality->rms_reprojection_px;
    const auto& inliers = quality->num_inliers;
    const int64_t tri_points = static_cast<int64_t>(header.keypoint_names.size());
    if (rms.shape == std::vector<int64_t>{shape[0], tri_points} && inliers.shape == rms.shape) {
      data.reprojection_px.shape = {shape[0], shape[1]};
      data.reprojection_px.data.assign(shape[0] * shape[1], kNaN);
      data.views.shape = {shape[0], shape[1]};
      data.views.data.assign(shape[0] * shape[1], 0);
      for (int64_t p = 0; p < shape[1]; ++p) {
        int t = -1;
        for (int64_t i = 0; i < tri_points && t < 0; ++i) {
          if (header.keypoint_names[i] == data.keypoint_names[p]) t = static_cast<int>(i);
        }
        if (t < 0) continue;
        for (int64_t f = 0; f < shape[0]; ++f) {
          data.reprojection_px.at(f, p) = rms.at(f, t);
          data.views.at(f, p) = inliers.at(f, t);
        }
      }
    }
  }
  ARCO_ASSIGN_OR_RETURN(const bool has_instrument, folder.HasStage(pipeline::kInstrumentStage));
  if (has_instrument) {
    ARCO_ASSIGN_OR_RETURN(pipeline::InstrumentRecord inst, folder.ReadInstrument());
    data.instrument = inst.instrument;
    const auto& s = inst.strings_mm.shape;
    if (s.size() == 4 && s[0] == shape[0] && s[2] == 2 && s[3] == 3) {
      ARCO_RETURN_IF_ERROR(
          CheckCoordinates(inst.strings_mm.data, folder.InstrumentStringsPath(), [&](int64_t i) {
            return "frame " + std::to_string(data.frame_first + i / (s[1] * 2)) + " string " +
                   std::to_string(i / 2 % s[1] + 1);
          }));
      data.strings_mm = std::move(inst.strings_mm);
    }
  }
  return data;
}

std::string CsvText(const ExportData& data) {
  std::string out = "frame,time_s,keypoint,x_mm,y_mm,z_mm,present,reprojection_px,views\n";
  const bool quality = !data.reprojection_px.shape.empty();
  out.reserve(out.size() + data.frames() * data.points() * 48);
  for (int64_t f = 0; f < data.frames(); ++f) {
    const std::string frame = std::to_string(data.frame_first + f) + ",";
    char time[32];
    std::snprintf(time, sizeof(time), "%.6f,", f / data.fps);
    for (int p = 0; p < data.points(); ++p) {
      out += frame;
      out += time;
      out += data.keypoint_names[p];
      const Eigen::Vector3d x = data.At(f, p);
      const bool present = x.allFinite();
      for (int k = 0; k < 3; ++k) {
        out += ',';
        if (present) AppendNumber(out, x[k]);
      }
      out += present ? ",1," : ",0,";
      const double rms = quality ? data.reprojection_px.at(f, p) : kNaN;
      if (std::isfinite(rms)) {
        char q[48];
        std::snprintf(q, sizeof(q), "%.3f,%d\n", rms, data.views.at(f, p));
        out += q;
      } else {
        out += ",\n";
      }
    }
  }
  return out;
}

// OpenSim's marker format (.trc, "PathFileType 4"): tab-separated, a gap is an empty field.
std::string TrcText(const ExportData& data, const std::string& file_name) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof(line), "PathFileType\t4\t(X/Y/Z)\t%s\n", file_name.c_str());
  out += line;
  out +=
      "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame"
      "\tOrigNumFrames\n";
  std::snprintf(line,
                sizeof(line),
                "%.6f\t%.6f\t%lld\t%d\tmm\t%.6f\t%lld\t%lld\n",
                data.fps,
                data.fps,
                static_cast<long long>(data.frames()),
                data.points(),
                data.fps,
                static_cast<long long>(data.frame_first),
                static_cast<long long>(data.frames()));
  out += line;
  out += "Frame#\tTime";
  for (const auto& name : data.keypoint_names) out += "\t" + name + "\t\t";
  out += "\n\t";
  for (int p = 1; p <= data.points(); ++p) {
    const std::string n = std::to_string(p);
    out += "\tX" + n + "\tY" + n + "\tZ" + n;
  }
  out += "\n\n";
  for (int64_t f = 0; f < data.frames(); ++f) {
    std::snprintf(line, sizeof(line), "%lld\t%.6f", static_cast<long long>(f + 1), f / data.fps);
    out += line;
    for (int p = 0; p < data.points(); ++p) {
      const Eigen::Vector3d x = data.At(f, p);
      for (int k = 0; k < 3; ++k) {
        out += '\t';
        if (x.allFinite()) AppendNumber(out, x[k]);
      }
    }
    out += '\n';
  }
  return out;
}

StatusOr<ExportSummary> ExportResult(const ExportOptions& options,
                                     const std::string& path,
                                     const std::string& display_name) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  ARCO_ASSIGN_OR_RETURN(const ExportFormat format, ParseExportFormat(options.format));
  ARCO_ASSIGN_OR_RETURN(const ExportData data, LoadExportData(options));
  ExportSummary summary;
  summary.format = format;
  summary.frames = data.frames();
  summary.keypoints = data.points();
  std::string bytes;
  switch (format) {
    case ExportFormat::kCsv:
      bytes = CsvText(data);
      break;
    case ExportFormat::kTrc:
      bytes = TrcText(data, display_name);
      break;
    case ExportFormat::kC3d: {
      ARCO_ASSIGN_OR_RETURN(bytes, C3dBytes(data));
      break;
    }
    case ExportFormat::kGltf:
      bytes = GlbBytes(data);
      break;
    case ExportFormat::kBvh: {
      ARCO_ASSIGN_OR_RETURN(BvhExport bvh, ExportBvh(data));
      bytes = std::move(bvh.text);
      summary.bvh_residuals = std::move(bvh.residuals);
      summary.bvh_body_median_mm = bvh.body_median_mm;
      summary.bvh_left_hand_median_mm = bvh.left_hand_median_mm;
      summary.bvh_right_hand_median_mm = bvh.right_hand_median_mm;
      break;
    }
  }
  summary.bytes = static_cast<int64_t>(bytes.size());
  ARCO_RETURN_IF_ERROR(AtomicWriteFile(path, bytes));
  return summary;
}

}  // namespace arco::exporter
