// `arco report`: a take's notes, intonation and bowing as one HTML page for a teacher
// (docs/report.md).
#include <cstdio>

#include "arco/cli/command.h"
#include "arco/cli/command_paths.h"
#include "arco/cli/flag_names.h"
#include "arco/cli/number_option.h"
#include "arco/export/teacher_report.h"
#include "arco/util/file_io.h"
#include "arco/util/output_set.h"

namespace arco::cli {
namespace {

inline constexpr FieldFlag kReportFlags[] = {{"result_dir", "RESULT_DIR"},
                                             {"method", "--method"},
                                             {"passage_gap_s", "--passage-gap-s"},
                                             {"in_tune_cents", "--in-tune-cents"}};

struct Args {
  exporter::TeacherReportOptions options;
  std::string output;
};

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

int Run(const Args& a) {
  OutputSet outputs;
  auto tmp = outputs.AddFile(a.output);
  if (!tmp.ok()) return PrintError(tmp.status().message());
  exporter::TeacherReportSummary summary;
  auto page = exporter::BuildTeacherReport(a.options, &summary);
  if (!page.ok()) return PrintError(WithFlagNames(page.status().message(), kReportFlags));
  const Status written = AtomicWriteFile(*tmp, *page);
  if (!written.ok()) return PrintError(written.message());
  const Status committed = outputs.Commit();
  if (!committed.ok()) return PrintError(committed.message());
  std::printf("arco report: method %s, %d notes in %d passages, %d shifts%s -> %s\n",
              a.options.method.c_str(), summary.notes, summary.passages, summary.shifts,
              summary.bowing ? ", with bowing" : " (no bowing_notes.csv: no bow columns)",
              a.output.c_str());
  return 0;
}

CommandRun SetupReport(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "report", "A teacher's report of a result: every note's string, finger, intonation, "
                "vibrato and bowing, per passage, with the plots (one HTML page)");
  auto a = std::make_shared<Args>();
  cmd->add_option("result_dir", a->options.result_dir, "Result folder (from arco run)")->required();
  cmd->add_option("--method", a->options.method, "Whose fingering and bowing: arco or paper")
      ->capture_default_str();
  AddNumber(cmd, "--passage-gap-s", a->options.passage_gap_s,
            "A silence this long ends a passage (s)", exporter::kReportPassageGapRangeS)
      ->capture_default_str();
  AddNumber(cmd, "--in-tune-cents", a->options.in_tune_cents,
            "Within this many cents a note is in tune", exporter::kReportInTuneRangeCents)
      ->capture_default_str();
  cmd->add_option("-o,--output", a->output, "Output page (.html; an existing file is replaced)")
      ->required();
  cmd->parse_complete_callback([a] {
    const Status valid = a->options.Validate();
    if (!valid.ok()) throw CLI::ValidationError(WithFlagNames(valid.message(), kReportFlags));
    if (!EndsWith(a->output, ".html") && !EndsWith(a->output, ".htm")) {
      throw CLI::ValidationError("-o " + a->output + ": the report is HTML: name it .html");
    }
  });
  return CommandRun([a] { return Run(*a); },
                    [a] {
                      PathRoles roles;
                      AddResultInputs(&roles, "RESULT_DIR", a->options.result_dir);
                      roles.AddOutput("-o", a->output);
                      return roles;
                    });
}

}  // namespace
ARCO_REGISTER_COMMAND(report, 78, SetupReport);
}  // namespace arco::cli
