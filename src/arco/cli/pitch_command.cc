// `arco pitch`: pitch at video-frame times (pitch.csv), notes, MIDI.
#include <cstdio>
#include <memory>

#include "arco/cli/audio_report.h"
#include "arco/cli/command.h"
#include "arco/cli/command_paths.h"
#include "arco/cli/flag_names.h"
#include "arco/cli/number_option.h"
#include "arco/cli/progress.h"

namespace arco::cli {
namespace {

CommandRun SetupPitch(CLI::App& app) {
  auto o = std::make_shared<capture::PitchRunOptions>();
  auto* cmd = app.add_subcommand(
      "pitch", "Pitch (f0) at video-frame times: pitch.csv with one row per frame");
  cmd->add_option("input", o->input, "Audio file (WAV/FLAC/OGG/...) or a video with audio");
  cmd->add_option("--capture",
                  o->capture_dir,
                  "Capture folder: audio file, offset, fps, frame count, instrument and A4 "
                  "from its capture.json (options given here win)");
  cmd->add_option(
      "--instrument",
      o->instrument,
      "violin | viola | cello | double_bass (alias bass) | any: the pitch range (default cello)");
  AddNumber(cmd,
            "--fps",
            o->fps,
            "Video frame rate: one row per frame (Hz; default 30)",
            audio::kTrackerFpsRange);
  auto* start = AddNumber(cmd,
                          "--start-s",
                          o->start_s,
                          "Audio time of video frame 0 (s; default 0); row i at start + i/fps",
                          audio::kTrackerStartRangeS);
  AddNumber(cmd,
            "--offset-s",
            o->start_s,
            "Same as --start-s: the offset `arco sync` prints (s)",
            audio::kTrackerStartRangeS)
      ->excludes(start);
  AddNumber(cmd,
            "--frames",
            o->frames,
            "Number of video frames (default: to the end of audio)",
            Closed(1, kFrameCountRange.max));
  AddNumber(cmd,
            "--hops-per-frame",
            o->hops_per_frame,
            "Analysis hops per video frame (0: auto, fine rate >= 100 Hz)",
            audio::kHopsPerFrameRange)
      ->capture_default_str();
  AddNumber(cmd,
            "--fmin",
            o->min_f0_hz,
            "Override the lowest f0 (Hz; 0 = the instrument's; else >= 20 and below the highest)",
            audio::kF0OverrideRangeHz);
  AddNumber(cmd,
            "--fmax",
            o->max_f0_hz,
            "Override the highest f0 (Hz; 0 = the instrument's; at most 4000 for cello and double "
            "bass, 8000 for violin and viola: the analysis rate / 4)",
            audio::kF0OverrideRangeHz);
  AddNumber(cmd, "--a4", o->a4_hz, "Tuning reference A4 (Hz; default 440)", kA4RangeHz);
  cmd->add_option(
         "-o,--output", o->output, "pitch.csv to write: frame,time_s,f0_hz,confidence,voiced")
      ->capture_default_str();
  cmd->add_option("--fine", o->fine_output, "Also write the fine-hop track (same columns)");
  cmd->add_option("--notes",
                  o->notes_output,
                  "Write notes.csv: notes (onset, offset, median f0, MIDI, cents vs ET at A4, "
                  "vibrato rate Hz and extent cents) and glides");
  cmd->add_flag("--double-stops",
                o->double_stops,
                "Also estimate a second simultaneous note: pitch.csv gains f0_2_hz (0 when none)");
  cmd->add_option("--midi",
                  o->midi_output,
                  "Write the notes as a standard MIDI file with pitch bends (+-2 semitones)");
  cmd->parse_complete_callback([o] {
    const Status valid = o->Validate();
    if (!valid.ok()) throw CLI::ValidationError(WithFlagNames(valid.message(), kPitchFlags));
  });
  auto paths = [o] {
    PathRoles roles;
    roles.AddInput("INPUT", o->input);
    AddCaptureInputs(&roles, "--capture", o->capture_dir);
    roles.AddOutput("-o", o->output);
    roles.AddOutput("--fine", o->fine_output);
    roles.AddOutput("--notes", o->notes_output);
    roles.AddOutput("--midi", o->midi_output);
    return roles;
  };
  return CommandRun(
      [o] {
        ProgressBar bar("pitch");  // the bar starts at TrackPitch's SetTotal
        auto result = capture::RunPitch(*o, bar);
        bar.Finish();
        if (!result.ok()) return PrintError(WithFlagNames(result.status().message(), kPitchFlags));
        std::fputs(FormatPitchReport(*o, *result).c_str(), stdout);
        for (const std::string& w : PitchWarnings(*result)) PrintWarning(w);
        return 0;
      },
      paths);
}

}  // namespace
ARCO_REGISTER_COMMAND(pitch, 100, SetupPitch);
}  // namespace arco::cli
