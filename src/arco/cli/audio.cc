#include "arco/cli/audio.h"

#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <utility>

#include "arco/cli/flag_names.h"
#include "arco/mocap/capture.h"
#include "arco/util/file_io.h"
#include "arco/util/output_set.h"

namespace arco::cli {
namespace {

std::string InstrumentFromManifest(const std::string& name) {
  if (name == "none" || name.empty()) return "any";
  return name;
}

std::string Format(const char* format, ...) __attribute__((format(printf, 1, 2)));
std::string Format(const char* format, ...) {
  char buffer[512];
  va_list args;
  va_start(args, format);
  std::vsnprintf(buffer, sizeof(buffer), format, args);
  va_end(args);
  return buffer;
}

}  // namespace

StatusOr<PitchRunResult> RunPitch(const PitchRunOptions& o, Progress& progress) {
  PitchRunResult result;
  std::string instrument = o.instrument;
  double fps = o.fps, start_s = o.start_s, a4_hz = o.a4_hz;
  int64_t frames = o.frames;
  result.input = o.input;
  if (!o.capture_dir.empty()) {
    ARCO_ASSIGN_OR_RETURN(const CaptureManifest manifest, ReadCaptureManifest(o.capture_dir));
    if (result.input.empty()) {
      if (manifest.audio.empty()) {
        return Status::Error(JoinPath(o.capture_dir, kCaptureManifestName) +
                             ": no audio file in the manifest; give one on the command line");
      }
      result.input = ResolveCapturePath(o.capture_dir, manifest.audio);
    }
    if (instrument.empty()) instrument = InstrumentFromManifest(manifest.instrument);
    if (std::isnan(fps)) fps = manifest.fps;
    if (std::isnan(start_s)) start_s = manifest.audio_offset_s;
    if (std::isnan(a4_hz)) a4_hz = manifest.tuning_a4_hz;
    if (frames < 0 && manifest.frame_count > 0) frames = manifest.frame_count;
  }
  if (result.input.empty()) return Status::Error("no input: give an audio file or --capture");
  ARCO_ASSIGN_OR_RETURN(auto range,
                        audio::InstrumentRangeByName(instrument.empty() ? "cello" : instrument));
  auto& t = result.tracker;
  t.range = range;
  if (o.min_f0_hz > 0) t.range.min_f0_hz = o.min_f0_hz;
  if (o.max_f0_hz > 0) t.range.max_f0_hz = o.max_f0_hz;
  t.fps = std::isnan(fps) ? 30.0 : fps;
  t.start_s = std::isnan(start_s) ? 0.0 : start_s;
  t.a4_hz = std::isnan(a4_hz) ? 440.0 : a4_hz;
  t.max_frames = frames;
  t.hops_per_frame = o.hops_per_frame;
  ARCO_RETURN_IF_ERROR(t.Validate());
  // Every output declared and checked before the work, written together at the end.
  OutputSet outputs;
  ARCO_ASSIGN_OR_RETURN(const std::string pitch_tmp, outputs.AddFile(o.output));
  std::string fine_tmp, notes_tmp, midi_tmp;
  for (auto [path, tmp] : {std::pair{&o.fine_output, &fine_tmp},
                           std::pair{&o.notes_output, &notes_tmp},
                           std::pair{&o.midi_output, &midi_tmp}}) {
    if (path->empty()) continue;
    ARCO_ASSIGN_OR_RETURN(*tmp, outputs.AddFile(*path));
  }
  ARCO_ASSIGN_OR_RETURN(const audio::PitchTrack track,
                        audio::TrackPitchFile(result.input, t, &result.summary, progress));
  result.fine_fps = track.fine_fps;
  audio::NoteOptions note_options;
  note_options.a4_hz = t.a4_hz;
  const audio::NoteAnalysis notes = audio::SegmentNotes(track.fine, track.fine_fps, note_options);
  result.notes = static_cast<int>(notes.notes.size());
  result.glides = static_cast<int>(notes.glides.size());
  for (const auto& n : notes.notes) result.notes_with_vibrato += n.vibrato_rate_hz > 0;
  ARCO_RETURN_IF_ERROR(audio::WritePitchCsv(pitch_tmp, track.frames));
  if (!fine_tmp.empty()) ARCO_RETURN_IF_ERROR(audio::WritePitchCsv(fine_tmp, track.fine));
  if (!notes_tmp.empty()) ARCO_RETURN_IF_ERROR(audio::WriteNotesCsv(notes_tmp, notes));
  if (!midi_tmp.empty()) {
    ARCO_RETURN_IF_ERROR(audio::WriteMidiFile(
        midi_tmp,
        audio::NotesToMidi(
            notes, track.fine, note_options, audio::GmProgramForInstrument(t.range.name))));
  }
  ARCO_RETURN_IF_ERROR(outputs.Commit());
  return result;
}

std::string FormatPitchReport(const PitchRunOptions& o, const PitchRunResult& r) {
  const auto& s = r.summary;
  std::string out;
  out += Format("%s: %s, %d Hz, %d ch, %.2f s (analysed at %d Hz, %s %.0f-%.0f Hz)\n",
                r.input.c_str(),
                s.source_format.c_str(),
                s.source_rate_hz,
                s.source_channels,
                s.duration_s,
                s.analysis_rate_hz,
                r.tracker.range.name.c_str(),
                r.tracker.range.min_f0_hz,
                r.tracker.range.max_f0_hz);
  out += Format("frames: %lld at %.3f fps from %.4f s (fine hop %.2f ms)\n",
                static_cast<long long>(s.frames),
                r.tracker.fps,
                r.tracker.start_s,
                1000.0 / r.fine_fps);
  out += Format("voiced: %.1f%%", 100.0 * s.voiced_fraction);
  if (s.max_f0_hz > 0) out += Format(", range %.2f-%.2f Hz", s.min_f0_hz, s.max_f0_hz);
  out += "\n";
  out +=
      Format("notes: %d (%d with vibrato), glides: %d\n", r.notes, r.notes_with_vibrato, r.glides);
  for (const auto& w : s.warnings) out += "warning: " + WithFlagNames(w, kPitchFlags) + "\n";
  out += Format("wrote %s; %.3f s CPU (%.0fx real time)\n",
                o.output.c_str(),
                s.cpu_seconds,
                s.cpu_seconds > 0 ? s.duration_s / s.cpu_seconds : 0.0);
  return out;
}

StatusOr<audio::SyncResult> RunSync(const SyncRunOptions& o) {
  ARCO_RETURN_IF_ERROR(o.sync.Validate());
  CaptureManifest manifest;
  if (!o.capture_dir.empty()) {
    ARCO_ASSIGN_OR_RETURN(manifest, ReadCaptureManifest(o.capture_dir));
  }
  audio::SyncOptions sync = o.sync;
  if (!o.capture_dir.empty() && sync.video_fps <= 0) sync.video_fps = manifest.fps;
  ARCO_ASSIGN_OR_RETURN(audio::SyncResult result, audio::SyncAudioToVideo(o.audio, o.video, sync));
  if (!o.capture_dir.empty()) {
    // The manifest's offset is the audio time of its first frame, video frame 0.
    manifest.audio_offset_s = result.offset_s;
    if (manifest.audio.empty()) {
      manifest.audio = std::filesystem::relative(std::filesystem::absolute(o.audio),
                                                 std::filesystem::absolute(o.capture_dir))
                           .string();
    }
    ARCO_RETURN_IF_ERROR(WriteCaptureManifest(o.capture_dir, manifest));
  }
  return result;
}

std::string FormatSyncReport(const SyncRunOptions& o, const audio::SyncResult& r) {
  std::string out;
  out += Format("audio %s: onset at %.4f s (%.1f dB; next strongest %.1f dB)\n",
                o.audio.c_str(),
                r.audio.time_s,
                r.audio.strength,
                r.audio.runner_up);
  out += Format("video %s: event at %.4f s = frame %.2f of %.3f fps (motion %.1f; next %.1f)\n",
                o.video.c_str(),
                r.video.time_s,
                r.video.time_s * r.video_fps,
                r.video_fps,
                r.video.strength,
                r.video.runner_up);
  out +=
      Format("offset_s %.4f  (audio time = video time + offset; use arco pitch --offset-s %.4f)\n",
             r.offset_s,
             r.offset_s);
  for (const auto& w : r.warnings) out += "warning: " + WithFlagNames(w, kSyncFlags) + "\n";
  if (!o.capture_dir.empty()) {
    out += "wrote audio.offset_s to " + JoinPath(o.capture_dir, kCaptureManifestName) + "\n";
  }
  return out;
}

}  // namespace arco::cli
