#include "arco/calibration/calibrate.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <thread>

#include "arco/calibration/calibration_file.h"
#include "arco/util/output_set.h"
#include "arco/util/parallel.h"

namespace arco::calibration {

Status CalibrateOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(ParseBoardSpec(board).status());
  std::set<std::string> names;
  for (const CalibrateInput& input : inputs) {
    if (input.camera.empty() || input.path.empty())
      return Status::Error("inputs: a camera needs a name and a path (CAMERA=PATH)");
    if (!names.insert(input.camera).second)
      return Status::Error("inputs: camera '" + input.camera + "' is given twice");
  }
  if (output.empty()) return Status::Error("output: no calibration file given");
  ARCO_RETURN_IF_ERROR(CheckInRange("num_threads", num_threads, Closed(0, 1024)));
  ARCO_RETURN_IF_ERROR(detection.Validate());
  return calibration.Validate();
}

StatusOr<CalibrateInput> ParseCalibrateInput(const std::string& text) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
    return Status::Error("'" + text + "' is not CAMERA=PATH");
  return CalibrateInput{text.substr(0, eq), text.substr(eq + 1)};
}

std::string ReportPath(const std::string& calibration_path) {
  const std::filesystem::path path(calibration_path);
  std::filesystem::path report = path;
  if (path.has_extension()) report.replace_extension();
  return report.string() + ".report.json";
}

StatusOr<CalibrateResult> RunCalibrate(const CalibrateOptions& options, Progress& progress) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  ARCO_ASSIGN_OR_RETURN(const BoardSpec board, ParseBoardSpec(options.board));
  CalibrateResult result;
  result.report_path = ReportPath(options.output);
  // Outputs first: a bad location fails before the detection.
  ARCO_RETURN_IF_ERROR(CheckOutputFile(options.output));
  ARCO_RETURN_IF_ERROR(CheckOutputFile(result.report_path));
  const std::string extension = std::filesystem::path(options.output).extension().string();
  if (extension != ".json" && extension != ".yaml" && extension != ".yml" && extension != ".xml")
    return Status::Error(options.output +
                         ": unknown calibration extension (.json arco JSON, .yaml/.yml OpenCV "
                         "YAML, .xml OpenCV XML)");
  if (options.inputs.size() < 2)
    return Status::Error(
        "a rig calibration needs at least two cameras, got " +
        std::to_string(options.inputs.size()) +
        (options.inputs.size() == 1 ? " (" + options.inputs[0].camera + ")" : std::string()));
  // Two cameras reading one source would calibrate as a zero-baseline rig that
  // triangulates nothing: refused before the detection.
  for (size_t a = 0; a < options.inputs.size(); ++a)
    for (size_t b = a + 1; b < options.inputs.size(); ++b) {
      std::error_code ec;
      if (options.inputs[a].path == options.inputs[b].path ||
          std::filesystem::equivalent(options.inputs[a].path, options.inputs[b].path, ec))
        return Status::Error(options.inputs[b].path + ": cameras '" + options.inputs[a].camera +
                             "' and '" + options.inputs[b].camera +
                             "' are given the same video or image folder (each camera needs its "
                             "own)");
    }
  std::optional<Calibration> intrinsics;
  if (!options.intrinsics.empty()) {
    ARCO_ASSIGN_OR_RETURN(intrinsics, LoadCalibration(options.intrinsics));
    // Intrinsics are matched by camera name; a file naming none of the cameras would be
    // ignored without a word.
    std::string given, wanted;
    bool any = false;
    for (const Camera& c : intrinsics->rig.cameras) given += (given.empty() ? "" : ", ") + c.name;
    for (const CalibrateInput& input : options.inputs) {
      wanted += (wanted.empty() ? "" : ", ") + input.camera;
      any = any || intrinsics->rig.FindCamera(input.camera) >= 0;
    }
    if (!any)
      return Status::Error(options.intrinsics + ": names none of the cameras being calibrated (" +
                           wanted + "); it has " + given +
                           " (intrinsics are matched by camera name)");
  }

  const int n = static_cast<int>(options.inputs.size());
  // Progress counts cameras whose detection is done (no stage lines: an error is then the
  // command's only line on stderr).
  std::vector<StatusOr<CameraBoardViews>> detected(n, Status::Error("not run"));
  progress.SetTotal(n);
  ParallelFor(
      n,
      options.num_threads,
      [&](int64_t i, int) {
        detected[i] = DetectBoardInVideo(board,
                                         options.inputs[i].camera,
                                         options.inputs[i].path,
                                         options.detection,
                                         NoProgress());
        progress.Advance(1);
      },
      1);
  for (auto& d : detected) {
    if (!d.ok()) return d.status();
    result.detections.push_back(std::move(*d));
  }
  ARCO_ASSIGN_OR_RETURN(
      result.calibration,
      CalibrateRig(
          options.calibration, board, result.detections, intrinsics ? &intrinsics->rig : nullptr));

  OutputSet outputs;
  ARCO_ASSIGN_OR_RETURN(const std::string calibration_tmp, outputs.AddFile(options.output));
  ARCO_ASSIGN_OR_RETURN(const std::string report_tmp, outputs.AddFile(result.report_path));
  CalibrationFormat format = CalibrationFormat::kArcoJson;
  if (extension == ".yaml" || extension == ".yml") format = CalibrationFormat::kOpenCvYaml;
  if (extension == ".xml") format = CalibrationFormat::kOpenCvXml;
  ARCO_RETURN_IF_ERROR(SaveCalibration(calibration_tmp, result.calibration.rig, format));
  {
    std::ofstream out(report_tmp);
    out << result.calibration.report.ToJson().dump(2) << "\n";
    if (!out) return Status::Error(result.report_path + ": cannot write");
  }
  ARCO_RETURN_IF_ERROR(outputs.Commit());
  return result;
}

}  // namespace arco::calibration
