// The terminal text of `arco pitch` and `arco sync` (the work is capture/pitch_sync.h).
#include "arco/cli/audio_report.h"

#include <cmath>
#include <cstdarg>
#include <cstdio>

#include "arco/cli/flag_names.h"
#include "arco/mocap/capture.h"
#include "arco/util/file_io.h"

namespace arco::cli {
namespace {

std::string Format(const char* format, ...) __attribute__((format(printf, 1, 2)));
std::string Format(const char* format, ...) {
  char buffer[1024];
  va_list args;
  va_start(args, format);
  std::vsnprintf(buffer, sizeof(buffer), format, args);
  va_end(args);
  return buffer;
}

}  // namespace

std::string FormatPitchReport(const capture::PitchRunOptions& o, const capture::PitchRunResult& r) {
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
  if (o.double_stops) {
    out += Format("double stops: a second note on %lld frames (f0_2_hz), %d second-voice notes\n",
                  static_cast<long long>(r.double_stop_frames),
                  r.second_voice_notes);
  }
  out += Format("wrote %s; %.3f s CPU (%.0fx real time)\n",
                o.output.c_str(),
                s.cpu_seconds,
                s.cpu_seconds > 0 ? s.duration_s / s.cpu_seconds : 0.0);
  return out;
}

std::string FormatSyncReport(const capture::SyncRunOptions& o, const capture::SyncRunResult& run) {
  const audio::SyncResult& r = run.sync;
  std::string out;
  out += Format("audio %s: onset at %.4f s (%.1f dB over the preceding 50 ms; runner-up %.1f dB",
                o.audio.c_str(),
                r.audio.time_s,
                r.audio.strength,
                r.audio.runner_up);
  if (!std::isnan(r.audio.runner_up_time_s)) out += Format(" at %.3f s", r.audio.runner_up_time_s);
  out += Format("; peak %.1f dBFS, floor %.1f dBFS)\n", r.audio.level, r.audio.floor);
  for (const audio::SyncViewResult& v : r.views) {
    if (!v.error.empty()) {
      out += "video " + v.video + ": left out\n";
      continue;
    }
    out += Format(
        "video %s: event at %.4f s = frame %.2f of %.3f fps%s (motion change %.3f; "
        "runner-up %.3f",
        v.video.c_str(),
        v.event.time_s,
        v.event.time_s * v.fps,
        v.fps,
        run.first_frame >= 0 ? Format(", global frame %.2f", v.global_frame).c_str() : "",
        v.event.strength,
        v.event.runner_up);
    if (!std::isnan(v.event.runner_up_time_s)) {
      out += Format(" at %.3f s", v.event.runner_up_time_s);
    }
    out += Format("; jitter %.3f)%s\n", v.event.noise, v.used ? "" : " disagrees: left out");
  }
  if (run.first_frame >= 0) {
    out += Format("offset_s %.4f  (audio time of frame %lld, frames.first; confidence %.2f)\n",
                  run.offset_s,
                  static_cast<long long>(run.first_frame),
                  r.confidence);
  } else {
    out += Format(
        "offset_s %.4f  (audio time = video time + offset; use arco pitch --offset-s %.4f; "
        "confidence %.2f)\n",
        run.offset_s,
        run.offset_s,
        r.confidence);
  }
  if (run.wrote_capture) {
    out += "wrote audio.offset_s and audio.sync_confidence to " +
           CaptureManifestPath(o.capture_dir) + "\n";
  }
  return out;
}

std::vector<std::string> PitchWarnings(const capture::PitchRunResult& result) {
  std::vector<std::string> out;
  for (const auto& w : result.summary.warnings) out.push_back(WithFlagNames(w, kPitchFlags));
  return out;
}

std::vector<std::string> SyncWarnings(const capture::SyncRunResult& result) {
  std::vector<std::string> out;
  for (const auto& w : result.sync.warnings) out.push_back(WithFlagNames(w, kSyncFlags));
  return out;
}

}  // namespace arco::cli
