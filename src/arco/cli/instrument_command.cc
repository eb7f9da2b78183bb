// `arco instrument NAME [--a4-hz F] [--offset-cents c1,c2,c3,c4] [--f0-hz F] [--correction]`:
// print an instrument model (open strings, ranges, sizes) and, with --f0-hz, where a
// finger must press on each string to sound that pitch (instrument/contact.h).
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "arco/cli/command.h"
#include "arco/cli/number_option.h"
#include "arco/instrument/contact.h"
#include "arco/instrument/instrument_model.h"

namespace arco::cli {
namespace {

struct InstrumentCommandOptions {
  std::string instrument = "cello";
  double a4_hz = 440.0;
  std::vector<double> offset_cents;  // per string, string 1 (highest) first
  double f0_hz = 0;                  // 0 = no contact query
  bool correction = false;
};

int RunInstrument(const InstrumentCommandOptions& o) {
  auto kind = ParseInstrumentKind(o.instrument);
  if (!kind.ok()) return PrintError(kind.status().message());
  InstrumentOptions options;
  options.kind = *kind;
  options.tuning.a4_hz = o.a4_hz;
  options.tuning.offset_cents = o.offset_cents;
  auto model = InstrumentModel::Create(options);
  if (!model.ok()) return PrintError(model.status().message());
  std::printf(
      "%s: string length %.1f mm, outer strings %.1f mm apart at the nut, %.1f mm "
      "at the bridge, A4 = %.2f Hz\n",
      model->name(),
      model->string_length_mm(),
      model->nut_spacing_mm(),
      model->bridge_spacing_mm(),
      o.a4_hz);
  std::printf("%-7s %-5s %10s %10s\n", "string", "note", "open_hz", "max_hz");
  for (int s = 1; s <= model->num_strings(); ++s) {
    std::printf("%-7d %-5s %10.2f %10.2f\n",
                s,
                model->open_note_name(s).c_str(),
                model->open_hz(s),
                model->max_hz(s));
  }
  if (o.f0_hz == 0) return 0;
  ContactOptions contact_options;
  contact_options.physical_correction = o.correction;
  std::printf("\nf0 = %.2f Hz (%s; distances along the string from the bridge)\n",
              o.f0_hz,
              o.correction ? "with finger-pad and string-height correction" : "ideal string");
  std::printf("%-7s %-12s %12s %18s %10s\n",
              "string",
              "kind",
              "cents_open",
              "contact_from_bridge",
              "fraction");
  for (const Contact& c : ContactCandidates(*model, o.f0_hz, contact_options)) {
    std::printf("%-7d %-12s %12.1f %15.1f mm %10.4f\n",
                c.string,
                ContactKindName(c.kind),
                c.cents_from_open,
                c.contact_from_bridge_mm,
                c.fraction_from_bridge);
  }
  return 0;
}

std::function<int()> SetupInstrument(CLI::App& app) {
  auto options = std::make_shared<InstrumentCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "instrument", "Print an instrument model and where a pitch is played on each string");
  cmd->add_option("name", options->instrument, "violin, viola, cello or double_bass")
      ->capture_default_str();
  AddNumber(cmd, "--a4-hz", options->a4_hz, "Concert pitch A4 in Hz", kA4RangeHz)
      ->capture_default_str();
  AddNumber(cmd,
            "--offset-cents",
            options->offset_cents,
            "Scordatura: cents per string from standard tuning, string 1 (highest) "
            "first, e.g. 0,0,-100,-100 (each within two octaves)",
            kTuningOffsetRangeCents)
      ->delimiter(',');
  AddNumber(cmd,
            "--f0-hz",
            options->f0_hz,
            "Pitch to locate on every string (Hz); 0 = none",
            Closed(0, 20000))
      ->capture_default_str();
  cmd->add_flag("--correction",
                options->correction,
                "Apply the finger-pad and string-height correction (instrument/contact.h)");
  return [options] { return RunInstrument(*options); };
}

}  // namespace
ARCO_REGISTER_COMMAND(instrument, 60, SetupInstrument);
}  // namespace arco::cli
