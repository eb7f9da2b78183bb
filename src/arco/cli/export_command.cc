// `arco export`: a result folder's points as CSV, TRC, C3D, glTF or BVH (docs/export.md).
#include <algorithm>
#include <cstdio>

#include "arco/cli/command.h"
#include "arco/cli/command_paths.h"
#include "arco/cli/flag_names.h"
#include "arco/export/export.h"
#include "arco/util/output_set.h"

namespace arco::cli {
namespace {

struct Args {
  exporter::ExportOptions options;  // options.output: -o, its extension checked by Validate
  bool residuals = false;
};

std::string BaseName(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

int Run(const Args& a) {
  OutputSet outputs;
  auto tmp = outputs.AddFile(a.options.output);
  if (!tmp.ok()) return PrintError(tmp.status().message());
  auto summary = exporter::ExportResult(a.options, *tmp, BaseName(a.options.output));
  if (!summary.ok()) return PrintError(WithFlagNames(summary.status().message(), kExportFlags));
  const Status committed = outputs.Commit();
  if (!committed.ok()) return PrintError(committed.message());
  std::printf("arco export: %s of method %s, %lld frames, %d keypoints, %lld bytes -> %s\n",
              exporter::ExportFormatName(summary->format),
              a.options.method.c_str(),
              static_cast<long long>(summary->frames),
              summary->keypoints,
              static_cast<long long>(summary->bytes),
              a.options.output.c_str());
  if (summary->format == exporter::ExportFormat::kBvh) {
    std::printf(
        "BVH fit residual, median: body %.3f mm, left hand %.3f mm, right hand %.3f mm (per "
        "joint in the file's header%s)\n",
        summary->bvh_body_median_mm,
        summary->bvh_left_hand_median_mm,
        summary->bvh_right_hand_median_mm,
        a.residuals ? ", and below" : "; --residuals prints them");
    if (a.residuals) {
      std::printf("%-24s %10s %10s %7s\n", "joint", "median_mm", "max_mm", "frames");
      for (const auto& r : summary->bvh_residuals) {
        std::printf("%-24s %10.4f %10.4f %7d\n", r.name.c_str(), r.median_mm, r.max_mm, r.frames);
      }
    }
  }
  return 0;
}

CommandRun SetupExport(CLI::App& app) {
  auto* cmd = app.add_subcommand("export",
                                 "Write a result's 3D points as CSV, TRC, C3D, glTF (.glb) or BVH");
  auto a = std::make_shared<Args>();
  cmd->add_option("result_dir", a->options.result_dir, "Result folder (from arco run)")->required();
  cmd->add_option("--format",
                  a->options.format,
                  "csv (long: frame, time_s, keypoint, x, y, z mm), trc (OpenSim markers, mm), "
                  "c3d (mm), gltf (binary .glb, metres), bvh (skeleton fit, mm)")
      ->required();
  cmd->add_option("--method", a->options.method, "Which method's points: arco, paper or vision")
      ->capture_default_str();
  cmd->add_option("-o,--output", a->options.output, "Output file")->required();
  cmd->add_flag("--residuals", a->residuals, "BVH: print the fit residual of every joint");
  cmd->parse_complete_callback([a] {
    const Status valid = a->options.Validate();
    if (!valid.ok()) throw CLI::ValidationError(WithFlagNames(valid.message(), kExportFlags));
  });
  return CommandRun([a] { return Run(*a); },
                    [a] {
                      PathRoles roles;
                      AddResultInputs(&roles, "RESULT_DIR", a->options.result_dir);
                      roles.AddOutput("-o", a->options.output);
                      return roles;
                    });
}

}  // namespace
ARCO_REGISTER_COMMAND(export, 75, SetupExport);
}  // namespace arco::cli
