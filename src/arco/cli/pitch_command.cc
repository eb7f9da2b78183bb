// `arco pitch`: pitch at video-frame times (pitch.csv), optional fine track.
#include <cmath>
#include <cstdio>

#include "arco/audio/notes.h"
#include "arco/audio/pitch_tracker.h"
#include "arco/cli/command.h"
#include "arco/cli/progress.h"

namespace arco::cli {
namespace {

struct PitchCommandOptions {
  std::string input;
  std::string instrument = "cello";
  double fps = 30.0;
  double start_s = 0.0;
  double offset_s = NAN;
  int64_t frames = -1;
  int hops_per_frame = 0;
  double a4_hz = 440.0;
  double min_f0_hz = 0, max_f0_hz = 0;
  std::string output = "pitch.csv";
  std::string fine_output;
  std::string notes_output;
  std::string midi_output;
};

int RunPitch(const PitchCommandOptions& o) {
  auto range = audio::InstrumentRangeByName(o.instrument);
  if (!range.ok()) return PrintError(range.status().message());
  audio::PitchTrackerOptions options;
  options.range = *range;
  if (o.min_f0_hz > 0) options.range.min_f0_hz = o.min_f0_hz;
  if (o.max_f0_hz > 0) options.range.max_f0_hz = o.max_f0_hz;
  options.fps = o.fps;
  options.start_s = std::isnan(o.offset_s) ? o.start_s : o.offset_s;
  options.max_frames = o.frames;
  options.hops_per_frame = o.hops_per_frame;
  options.a4_hz = o.a4_hz;
  Status valid = options.Validate();
  if (!valid.ok()) return PrintError(valid.message());
  audio::PitchSummary summary;
  ProgressBar bar("pitch", 1000);
  int64_t shown = 0;
  auto track = audio::TrackPitchFile(o.input, options, &summary, [&](double fraction) {
    const int64_t now = static_cast<int64_t>(fraction * 1000);
    if (now > shown) bar.Add(now - shown), shown = now;
  });
  bar.Finish();
  if (!track.ok()) return PrintError(track.status().message());
  Status written = audio::WritePitchCsv(o.output, track->frames);
  if (!written.ok()) return PrintError(written.message());
  if (!o.fine_output.empty()) {
    written = audio::WritePitchCsv(o.fine_output, track->fine);
    if (!written.ok()) return PrintError(written.message());
  }
  audio::NoteOptions note_options;
  note_options.a4_hz = o.a4_hz;
  audio::NoteAnalysis notes = audio::SegmentNotes(track->fine, track->fine_fps, note_options);
  if (!o.notes_output.empty()) {
    written = audio::WriteNotesCsv(o.notes_output, notes);
    if (!written.ok()) return PrintError(written.message());
  }
  if (!o.midi_output.empty()) {
    written = audio::WriteMidiFile(
        o.midi_output,
        audio::NotesToMidi(
            notes, track->fine, note_options, audio::GmProgramForInstrument(options.range.name)));
    if (!written.ok()) return PrintError(written.message());
  }
  int with_vibrato = 0;
  for (const auto& n : notes.notes) with_vibrato += n.vibrato_rate_hz > 0;
  std::printf("%s: %s, %d Hz, %d ch, %.2f s (analysed at %d Hz)\n",
              o.input.c_str(),
              summary.source_format.c_str(),
              summary.source_rate_hz,
              summary.source_channels,
              summary.duration_s,
              summary.analysis_rate_hz);
  std::printf("frames: %lld at %.3f fps from %.3f s (fine hop %.2f ms)\n",
              static_cast<long long>(summary.frames),
              o.fps,
              options.start_s,
              1000.0 / track->fine_fps);
  std::printf("voiced: %.1f%%", 100.0 * summary.voiced_fraction);
  if (summary.max_f0_hz > 0) {
    std::printf(", range %.2f-%.2f Hz", summary.min_f0_hz, summary.max_f0_hz);
  }
  std::printf("\n");
  std::printf("notes: %zu (%d with vibrato), glides: %zu\n",
              notes.notes.size(),
              with_vibrato,
              notes.glides.size());
  for (const auto& w : summary.warnings) std::printf("warning: %s\n", w.c_str());
  std::printf("wrote %s; %.3f s CPU (%.0fx real time)\n",
              o.output.c_str(),
              summary.cpu_seconds,
              summary.cpu_seconds > 0 ? summary.duration_s / summary.cpu_seconds : 0.0);
  return 0;
}

std::function<int()> SetupPitch(CLI::App& app) {
  auto options = std::make_shared<PitchCommandOptions>();
  auto* cmd = app.add_subcommand(
      "pitch", "Pitch (f0) at video-frame times: pitch.csv with one row per frame");
  cmd->add_option("input", options->input, "Audio file (WAV/FLAC/OGG) or a video with audio")
      ->required();
  cmd->add_option("--instrument",
                  options->instrument,
                  "violin | viola | cello | bass | any (sets the pitch range)")
      ->capture_default_str();
  cmd->add_option("--fps", options->fps, "Video frame rate: one row per frame (Hz)")
      ->capture_default_str();
  auto* start = cmd->add_option("--start-s",
                                options->start_s,
                                "Audio time of video frame 0 (s); row i is at start + i/fps")
                    ->capture_default_str();
  cmd->add_option("--offset-s",
                  options->offset_s,
                  "Same as --start-s: the offset printed by `arco sync` (s)")
      ->excludes(start);
  cmd->add_option("--frames", options->frames, "Number of video frames (default: to the end)");
  cmd->add_option("--hops-per-frame",
                  options->hops_per_frame,
                  "Analysis hops per video frame (0: auto, fine rate >= 100 Hz)")
      ->capture_default_str();
  cmd->add_option("--fmin", options->min_f0_hz, "Override the lowest f0 (Hz)");
  cmd->add_option("--fmax", options->max_f0_hz, "Override the highest f0 (Hz)");
  cmd->add_option("--a4", options->a4_hz, "Tuning reference A4 (Hz)")->capture_default_str();
  cmd->add_option("-o,--output", options->output, "pitch.csv to write")->capture_default_str();
  cmd->add_option("--fine", options->fine_output, "Also write the fine-hop track (CSV)");
  cmd->add_option("--notes",
                  options->notes_output,
                  "Write notes.csv: notes (onset, offset, median f0, MIDI, cents vs ET at --a4, "
                  "vibrato rate Hz and extent cents) and glides");
  cmd->add_option("--midi",
                  options->midi_output,
                  "Write the notes as a standard MIDI file with pitch bends (range +-2 semitones)");
  return [options] { return RunPitch(*options); };
}

}  // namespace
ARCO_REGISTER_COMMAND(pitch, 100, SetupPitch);
}  // namespace arco::cli
