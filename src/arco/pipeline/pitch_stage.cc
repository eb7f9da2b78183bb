#include "arco/pipeline/pitch_stage.h"

#include <algorithm>
#include <vector>

#include "arco/audio/double_stops.h"
#include "arco/audio/notes.h"
#include "arco/audio/pitch_tracker.h"
#include "arco/capture/pitch_sync.h"

namespace arco::pipeline {

Status PitchStageOptions::Validate() const { return Status::Ok(); }

StatusOr<PitchRecord> RunPitchStage(const PitchStageOptions& options,
                                    const CaptureContext& capture,
                                    Progress& progress) {
  const CaptureManifest& m = capture.manifest;
  PitchRecord record;
  PitchStageSummary& summary = record.summary;
  if (m.audio.empty()) {
    summary.warnings.push_back(
        "pitch: the capture has no audio; only the vision method is written");
    return record;
  }
  // The capture's values, as `arco pitch --capture` takes them from capture.json.
  capture::PitchRunOptions run;
  run.instrument = capture.instrument->name();
  run.fps = m.fps;
  run.start_s = m.audio_offset_s;
  run.frames = m.frame_count;
  run.a4_hz = m.tuning_a4_hz;
  ARCO_ASSIGN_OR_RETURN(const audio::PitchTrackerOptions po, capture::PitchTrackerOptionsFor(run));
  const std::string audio_path = ResolveCapturePath(capture.capture_dir, m.audio);
  audio::PitchSummary tracked;
  ARCO_ASSIGN_OR_RETURN(auto reader, OpenCaptureAudio(capture, audio_path));
  ARCO_ASSIGN_OR_RETURN(audio::PitchTrack track,
                        audio::TrackPitch(std::move(reader), po, &tracked, progress));
  // One row per video frame of the capture (audio shorter than the video: unvoiced).
  std::vector<audio::PitchFrame>& frames = record.frames;
  frames = track.frames;
  frames.resize(static_cast<size_t>(std::max<int64_t>(0, m.frame_count)));
  for (size_t i = track.frames.size(); i < frames.size(); ++i) {
    frames[i].frame = static_cast<int64_t>(i);
    frames[i].time_s = m.audio_offset_s + static_cast<double>(i) / m.fps;
  }
  if (track.frames.size() < frames.size()) {
    summary.warnings.push_back("pitch: the audio ends before the video; later frames are unvoiced");
  }
  for (const std::string& w : tracked.warnings) summary.warnings.push_back("pitch: " + w);
  audio::NoteOptions note_options;
  note_options.a4_hz = m.tuning_a4_hz;
  record.notes = audio::SegmentNotes(track.fine, track.fine_fps, note_options);
  summary.ran = true;
  summary.audio = audio_path;
  summary.duration_s = tracked.duration_s;
  summary.voiced_fraction = tracked.voiced_fraction;
  summary.notes = static_cast<int64_t>(record.notes.notes.size());
  record.a4_hz = m.tuning_a4_hz;
  if (options.double_stops) {
    // A second pass over the audio, one frame per row of pitch.csv.
    audio::DoubleStopOptions d;
    ARCO_ASSIGN_OR_RETURN(d.range, audio::InstrumentRangeByName(capture.instrument->name()));
    d.fps = m.fps;
    d.start_s = m.audio_offset_s;
    d.max_frames = static_cast<int64_t>(frames.size());
    d.a4_hz = m.tuning_a4_hz;
    ARCO_RETURN_IF_ERROR(d.Validate());
    ARCO_ASSIGN_OR_RETURN(auto poly_reader, OpenCaptureAudio(capture, audio_path));
    ARCO_ASSIGN_OR_RETURN(record.double_stops,
                          audio::TrackDoubleStops(std::move(poly_reader), d, nullptr));
    record.double_stops.resize(frames.size());  // audio shorter than the video: none
    for (size_t i = 0; i < frames.size(); ++i) {
      record.double_stops[i].frame = frames[i].frame;
      record.double_stops[i].time_s = frames[i].time_s;
    }
  }
  record.inputs = SelectInputs(capture.inputs, {kManifestInput, kAudioInput});
  return record;
}

}  // namespace arco::pipeline
