// `arco calibration show FILE [--json]` and `arco calibration convert IN OUT
// [--format F]`: inspect and convert camera calibrations (io/calibration_file.h).
#include <cmath>
#include <cstdio>
#include <memory>

#include "arco/calibration/calibration_file.h"
#include "arco/cli/command.h"
#include "arco/util/output_set.h"

namespace arco::cli {
namespace {

struct CalibrationShowOptions {
  std::string input;
  bool json = false;
};

struct CalibrationConvertOptions {
  std::string input;
  std::string output;
  std::string format;  // empty: from the output extension
};

void PrintWarnings(const Calibration& calibration) {
  for (const std::string& w : calibration.warnings)
    std::fprintf(stderr, "warning: %s\n", w.c_str());
}

int RunCalibrationShow(const CalibrationShowOptions& o) {
  auto calibration = calibration::LoadCalibration(o.input);
  if (!calibration.ok()) return PrintError(calibration.status().message());
  PrintWarnings(*calibration);
  const Rig& rig = calibration->rig;
  if (o.json) {
    nlohmann::ordered_json out;
    out["cameras"] = nlohmann::ordered_json::array();
    for (const Camera& cam : rig.cameras) out["cameras"].push_back(CameraToJson(cam));
    std::printf("%s\n", out.dump(2).c_str());
    return 0;
  }
  std::printf("%s: %s, %zu cameras, world units: %s\n",
              o.input.c_str(),
              CalibrationFormatName(calibration->format),
              rig.cameras.size(),
              rig.units.c_str());
  std::printf("pixels: OpenCV convention (origin at the centre of the top-left pixel)\n");
  std::printf("%-20s %-9s %-9s %9s %9s %8s %8s %8s %8s %9s %9s %8s  %s\n",
              "name",
              "serial",
              "size",
              "fx",
              "fy",
              "cx",
              "cy",
              "k1",
              "k2",
              "p1",
              "p2",
              "k3",
              "centre in world");
  for (const Camera& c : rig.cameras) {
    const Eigen::Vector3d centre = c.CenterInWorld();
    const std::string size = std::to_string(c.width) + "x" + std::to_string(c.height);
    std::printf(
        "%-20s %-9s %-9s %9.2f %9.2f %8.2f %8.2f %8.4f %8.4f %9.6f %9.6f %8.4f  %.4f %.4f %.4f\n",
        c.name.c_str(),
        c.serial.empty() ? "-" : c.serial.c_str(),
        size.c_str(),
        c.fx,
        c.fy,
        c.cx,
        c.cy,
        c.distortion.k1,
        c.distortion.k2,
        c.distortion.p1,
        c.distortion.p2,
        c.distortion.k3,
        centre.x(),
        centre.y(),
        centre.z());
  }
  return 0;
}

int RunCalibrationConvert(const CalibrationConvertOptions& o) {
  CalibrationFormat format = CalibrationFormat::kUnknown;
  if (!o.format.empty()) {
    auto parsed = calibration::CalibrationFormatFromFlag(o.format);
    if (!parsed.ok()) return PrintError(parsed.status().message());
    format = *parsed;
  }
  const Status writable = CheckOutputFile(o.output);  // before the work
  if (!writable.ok()) return PrintError(writable.message());
  auto calibration = calibration::LoadCalibration(o.input);
  if (!calibration.ok()) return PrintError(calibration.status().message());
  PrintWarnings(*calibration);
  Status saved = calibration::SaveCalibration(o.output, calibration->rig, format);
  if (!saved.ok()) return PrintError(saved.message());
  auto written = calibration::LoadCalibration(o.output);  // what a user will read back
  if (!written.ok()) return PrintError(written.status().message());
  std::printf("wrote %s (%s, %zu cameras, units %s) from %s (%s)\n",
              o.output.c_str(),
              CalibrationFormatName(written->format),
              written->rig.cameras.size(),
              written->rig.units.c_str(),
              o.input.c_str(),
              CalibrationFormatName(calibration->format));
  return 0;
}

CommandRun SetupCalibration(CLI::App& app) {
  auto* cmd = app.add_subcommand("calibration", "Show or convert a camera calibration");
  cmd->require_subcommand(1);
  auto show_options = std::make_shared<CalibrationShowOptions>();
  auto* show = cmd->add_subcommand(
      "show",
      "Print the cameras of a calibration (Metashape XML, SPD JSON, arco JSON, OpenCV "
      "YAML/XML; detected from the content). K uses OpenCV's pixel convention and "
      "x_cam = R X + t.");
  show->add_option("file", show_options->input, "Calibration file")->required();
  show->add_flag("--json",
                 show_options->json,
                 "Print {\"cameras\": [{name, serial, width, height, K[9], R[9], t[3], "
                 "distortion}]} instead of a table");
  auto convert_options = std::make_shared<CalibrationConvertOptions>();
  auto* convert = cmd->add_subcommand("convert", "Convert a calibration to another format");
  convert->add_option("input", convert_options->input, "Calibration file to read")->required();
  convert
      ->add_option("output",
                   convert_options->output,
                   "File to write (atomically); format from the extension: .yaml/.yml "
                   "OpenCV YAML, .xml OpenCV XML, .json arco JSON")
      ->required();
  convert
      ->add_option("--format",
                   convert_options->format,
                   "Output format instead of the extension: yaml, opencv-xml, spd, arco")
      ->check(CLI::IsMember({"yaml", "opencv-xml", "spd", "arco"}));
  auto paths = [convert, convert_options] {
    PathRoles roles;
    if (convert->parsed()) {
      roles.AddInput("INPUT", convert_options->input);
      roles.AddOutput("OUTPUT", convert_options->output);
    }
    return roles;
  };
  return CommandRun(
      [show, show_options, convert, convert_options]() {
        if (show->parsed()) return RunCalibrationShow(*show_options);
        if (convert->parsed()) return RunCalibrationConvert(*convert_options);
        return PrintError("calibration: give a subcommand (show, convert)");
      },
      paths);
}

}  // namespace
ARCO_REGISTER_COMMAND(calibration, 20, SetupCalibration);
}  // namespace arco::cli
