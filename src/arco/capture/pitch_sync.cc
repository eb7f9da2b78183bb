#include "arco/capture/pitch_sync.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <utility>

#include "arco/audio/double_stops.h"
#include "arco/capture/capture_checks.h"
#include "arco/mocap/capture.h"
#include "arco/util/file_io.h"
#include "arco/util/output_set.h"

namespace arco::capture {
namespace {

std::string InstrumentFromManifest(const std::string& name) {
  if (name == "none" || name.empty()) return "any";
  return name;
}

}  // namespace

Status PitchRunOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(CheckInRange("min_f0_hz", min_f0_hz, audio::kF0OverrideRangeHz));
  ARCO_RETURN_IF_ERROR(CheckInRange("max_f0_hz", max_f0_hz, audio::kF0OverrideRangeHz));
  if (min_f0_hz > 0 && max_f0_hz > 0 && !(min_f0_hz < max_f0_hz)) {
    return Status::Error("min_f0_hz must be below max_f0_hz");
  }
  return Status::Ok();
}

StatusOr<audio::PitchTrackerOptions> PitchTrackerOptionsFor(const PitchRunOptions& o) {
  ARCO_RETURN_IF_ERROR(o.Validate());
  ARCO_ASSIGN_OR_RETURN(
      auto range, audio::InstrumentRangeByName(o.instrument.empty() ? "cello" : o.instrument));
  audio::PitchTrackerOptions t;
  t.range = range;
  if (o.min_f0_hz > 0) t.range.min_f0_hz = o.min_f0_hz;
  if (o.max_f0_hz > 0) t.range.max_f0_hz = o.max_f0_hz;
  t.fps = std::isnan(o.fps) ? 30.0 : o.fps;
  t.start_s = std::isnan(o.start_s) ? 0.0 : o.start_s;
  t.a4_hz = std::isnan(o.a4_hz) ? 440.0 : o.a4_hz;
  t.max_frames = o.frames;
  t.hops_per_frame = o.hops_per_frame;
  ARCO_RETURN_IF_ERROR(t.Validate());
  return t;
}

StatusOr<PitchRunResult> RunPitch(const PitchRunOptions& o, Progress& progress) {
  ARCO_RETURN_IF_ERROR(o.Validate());
  PitchRunResult result;
  std::string instrument = o.instrument;
  double fps = o.fps, start_s = o.start_s, a4_hz = o.a4_hz;
  int64_t frames = o.frames;
  result.input = o.input;
  if (!o.capture_dir.empty()) {
    ARCO_ASSIGN_OR_RETURN(const CaptureManifest manifest, ReadCaptureManifest(o.capture_dir));
    if (result.input.empty()) {
      if (manifest.audio.empty()) {
        return Status::Error(CaptureManifestPath(o.capture_dir) +
                             ": no audio file in the manifest; give one on the command line");
      }
      result.input = ResolveCapturePath(o.capture_dir, manifest.audio);
    }
    if (instrument.empty()) instrument = InstrumentFromManifest(manifest.instrument);
    if (std::isnan(fps)) fps = manifest.fps;
    if (std::isnan(start_s)) start_s = manifest.audio_offset_s;
    if (std::isnan(a4_hz)) a4_hz = manifest.tuning_a4_hz;
    if (frames < 0 && manifest.frame_count > 0) frames = manifest.frame_count;
    // The manifest's audio at the manifest's offset: a bad offset is capture.json's
    // audio.offset_s, not a --start-s the user did not give.
    if (o.input.empty() && std::isnan(o.start_s)) {
      ARCO_RETURN_IF_ERROR(CheckCaptureAudio(o.capture_dir, manifest).status());
    }
  }
  if (result.input.empty()) return Status::Error("no input: give an audio file or --capture");
  PitchRunOptions resolved = o;
  resolved.instrument = instrument;
  resolved.fps = fps;
  resolved.start_s = start_s;
  resolved.a4_hz = a4_hz;
  resolved.frames = frames;
  ARCO_ASSIGN_OR_RETURN(result.tracker, PitchTrackerOptionsFor(resolved));
  const audio::PitchTrackerOptions& t = result.tracker;
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
  std::vector<double> second_f0_hz;
  if (o.double_stops) {
    audio::DoubleStopOptions d;
    d.range = t.range;
    d.fps = t.fps;
    d.start_s = t.start_s;
    d.max_frames = static_cast<int64_t>(track.frames.size());
    d.a4_hz = t.a4_hz;
    // A second pass over the audio (the tracker's stream is gone by now).
    ARCO_ASSIGN_OR_RETURN(const auto poly, audio::TrackDoubleStopsFile(result.input, d, nullptr));
    second_f0_hz = audio::SecondNoteHz(track.frames, poly);
    for (double f : second_f0_hz) result.double_stop_frames += f > 0;
  }
  ARCO_RETURN_IF_ERROR(
      audio::WritePitchCsv(pitch_tmp, track.frames, o.double_stops ? &second_f0_hz : nullptr));
  if (!fine_tmp.empty()) ARCO_RETURN_IF_ERROR(audio::WritePitchCsv(fine_tmp, track.fine));
  audio::NoteAnalysis second;  // the second voice's notes (double stops)
  if (o.double_stops) {
    second = audio::SecondVoiceNotes(track.frames, second_f0_hz, t.fps, note_options);
    result.second_voice_notes = static_cast<int>(second.notes.size());
  }
  if (!notes_tmp.empty() && o.double_stops) {
    // The second voice's notes merged by onset.
    audio::NoteAnalysis both = notes;
    both.notes.insert(both.notes.end(), second.notes.begin(), second.notes.end());
    std::stable_sort(
        both.notes.begin(), both.notes.end(), [](const audio::Note& a, const audio::Note& b) {
          return a.onset_s < b.onset_s;
        });
    ARCO_RETURN_IF_ERROR(audio::WriteNotesCsv(notes_tmp, both));
  } else if (!notes_tmp.empty()) {
    ARCO_RETURN_IF_ERROR(audio::WriteNotesCsv(notes_tmp, notes));
  }
  if (!midi_tmp.empty()) {
    const int program = audio::GmProgramForInstrument(t.range.name);
    audio::MidiFile midi = audio::NotesToMidi(notes, track.fine, note_options, program);
    if (o.double_stops) {
      // The second voice on a track and channel of its own (a pitch bend applies to a whole
      // channel), its bends from f0_2_hz at the video rate.
      std::vector<audio::PitchFrame> voice = track.frames;
      for (size_t i = 0; i < voice.size(); ++i) {
        voice[i].f0_hz = second_f0_hz[i];
        voice[i].voiced = second_f0_hz[i] > 0;
      }
      audio::MidiTrack upper =
          audio::NotesToMidi(second, voice, note_options, program).tracks.front();
      upper.name = "arco pitch, second voice";
      upper.channel = 1;
      midi.tracks.push_back(std::move(upper));
    }
    ARCO_RETURN_IF_ERROR(audio::WriteMidiFile(midi_tmp, midi));
  }
  ARCO_RETURN_IF_ERROR(outputs.Commit());
  return result;
}

StatusOr<SyncRunResult> RunSync(const SyncRunOptions& o) {
  ARCO_RETURN_IF_ERROR(o.sync.Validate());
  SyncRunResult out;
  CaptureManifest manifest;
  audio::SyncOptions sync = o.sync;
  std::vector<audio::SyncView> views;
  for (const std::string& video : o.videos) views.push_back({video, nullptr});
  if (!o.capture_dir.empty()) {
    ARCO_ASSIGN_OR_RETURN(manifest, ReadCaptureManifest(o.capture_dir));
    if (sync.video_fps <= 0) sync.video_fps = manifest.fps;
    out.first_frame = manifest.frame_first;
    // A camera's video frame index x (0-based) is its video frame x + 1, global frame
    // g = x + 1 + its drops up to g (docs/formats.md, "Dropped frames").
    auto camera_of = [&](const std::string& video) -> int {
      std::error_code ec;
      const auto target = std::filesystem::weakly_canonical(video, ec);
      for (size_t c = 0; c < manifest.cameras.size(); ++c) {
        if (manifest.cameras[c].video.empty()) continue;
        std::error_code ec2;
        const auto path = std::filesystem::weakly_canonical(
            ResolveCapturePath(o.capture_dir, manifest.cameras[c].video), ec2);
        if (!ec && !ec2 && path == target) return static_cast<int>(c);
      }
      return -1;
    };
    if (views.empty()) {
      for (const CaptureCamera& camera : manifest.cameras) {
        if (!camera.video.empty()) {
          views.push_back({ResolveCapturePath(o.capture_dir, camera.video), nullptr});
        }
      }
      if (views.empty()) {
        return Status::Error(CaptureManifestPath(o.capture_dir) +
                             ": no camera names a video; give one or more videos");
      }
    }
    for (audio::SyncView& view : views) {
      const int c = camera_of(view.video);
      std::vector<int64_t> drops;
      if (c >= 0) drops = manifest.cameras[static_cast<size_t>(c)].dropped_frames;
      std::sort(drops.begin(), drops.end());
      view.global_frame = [drops](double x) {
        const double whole = std::floor(x);
        double g = whole + 1;
        for (int64_t d : drops) {
          if (static_cast<double>(d) <= g) g += 1;
        }
        return g + (x - whole);
      };
    }
  }
  if (views.empty()) return Status::Error("no video to sync with: give one or a capture");
  ARCO_ASSIGN_OR_RETURN(out.sync, audio::SyncAudioToVideos(o.audio, views, sync));
  // A truncated audio file: the same warning as arco pitch and arco run (the header only).
  if (auto reader = audio::OpenAudio(o.audio); reader.ok()) {
    const std::string truncated = audio::TruncationWarning((*reader)->info());
    if (!truncated.empty()) out.sync.warnings.push_back(truncated);
  }
  out.offset_s = out.sync.offset_s;
  if (!o.capture_dir.empty()) {
    // sync.offset_s is the audio time of global frame 0; the manifest's offset is that
    // of frame frames.first.
    out.offset_s =
        out.sync.offset_s + static_cast<double>(manifest.frame_first) / out.sync.video_fps;
    manifest.audio_offset_s = out.offset_s;
    manifest.audio_sync_confidence = out.sync.confidence;
    if (manifest.audio.empty()) {
      manifest.audio = std::filesystem::relative(std::filesystem::absolute(o.audio),
                                                 std::filesystem::absolute(o.capture_dir))
                           .string();
    }
    ARCO_RETURN_IF_ERROR(WriteCaptureManifest(o.capture_dir, manifest));
    out.wrote_capture = true;
  }
  return out;
}

}  // namespace arco::capture
