// The work behind `arco pitch` and `arco sync` (cli/pitch_command.cc and
// cli/sync_command.cc parse argv into these options and print cli/report.h's text; tests
// and bindings call these directly).
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "arco/audio/notes.h"
#include "arco/audio/pitch_tracker.h"
#include "arco/audio/sync.h"
#include "arco/util/status.h"

namespace arco::capture {

struct PitchRunOptions {
  std::string input;        // audio file or video with an audio track
  std::string capture_dir;  // optional: audio, offset, fps, frames, instrument, A4 from
                            // CAPTURE_DIR/capture.json (explicit options below win)
  std::string instrument;   // violin | viola | cello | double_bass | any (default cello)
  double fps = NAN;         // default 30 (or the manifest's)
  double start_s = NAN;     // audio time of video frame 0 (default 0 or the manifest's)
  int64_t frames = -1;      // -1: to the end of the audio (or the manifest's count)
  int hops_per_frame = 0;
  double a4_hz = NAN;                   // default 440 (or the manifest's)
  double min_f0_hz = 0, max_f0_hz = 0;  // overrides of the instrument range
  std::string output = "pitch.csv";
  std::string fine_output, notes_output, midi_output;
  // Double stops (audio/double_stops.h): pitch.csv gains the column f0_2_hz, the second
  // note beside f0_hz (0 when none), and notes.csv its notes, overlapping the first
  // voice's (rows by onset). Off: both files are as without double stops.
  bool double_stops = false;

  // The overrides' ranges (audio::kF0OverrideRangeHz) and min below max when both are
  // given; the rest is checked by the tracker once the manifest's values are in.
  Status Validate() const;
};

struct PitchRunResult {
  std::string input;  // the audio actually read
  audio::PitchTrackerOptions tracker;
  audio::PitchSummary summary;
  double fine_fps = 0;
  int notes = 0, notes_with_vibrato = 0, glides = 0;
  int64_t double_stop_frames = 0;  // video frames with a second note (double_stops on)
  int second_voice_notes = 0;      // notes of the second voice in notes.csv
};

// The tracker's options for `o` without a capture folder (its manifest already applied):
// the instrument's range with the f0 overrides, the defaults for NaN fields, validated.
// RunPitch and the Python bindings' track_pitch share it.
StatusOr<audio::PitchTrackerOptions> PitchTrackerOptionsFor(const PitchRunOptions& o);

// Tracks, writes pitch.csv (and the optional outputs). Errors are one line that
// names the file.
StatusOr<PitchRunResult> RunPitch(const PitchRunOptions& options,
                                  Progress& progress = NoProgress());

struct SyncRunOptions {
  std::string audio;
  // Videos of synchronised cameras (their frame i shows the same instant); empty with
  // capture_dir: every camera of the capture that names a video.
  std::vector<std::string> videos;
  std::string capture_dir;  // optional: store the offset as the manifest's audio offset_s
  audio::SyncOptions sync;
};

struct SyncRunResult {
  audio::SyncResult sync;
  // The figure to use: with capture_dir the audio time of global frame frames.first
  // (what capture.json's audio.offset_s means and `arco run` / `arco pitch --capture`
  // read), else the audio time of the videos' frame 0 (`arco pitch --start-s`).
  double offset_s = 0;
  int64_t first_frame = -1;  // with capture_dir: its frames.first
  bool wrote_capture = false;
};

// Finds the event in the audio and every video; with capture_dir, maps each camera's
// video frames to global frames (skipping its dropped frames), writes audio.file (when
// empty), audio.offset_s and audio.sync_confidence into CAPTURE_DIR/capture.json.
// Nothing is written on an error.
StatusOr<SyncRunResult> RunSync(const SyncRunOptions& options);

}  // namespace arco::capture
