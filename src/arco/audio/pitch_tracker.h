// Pitch of a recording sampled at video-frame times.
//
// Timing contract: fine row j is at time_s = start_s + j / (fps * hops_per_frame);
// video row i is fine row i * hops_per_frame, i.e. time_s = start_s + i / fps
// exactly, and its analysis window is centred on the analysis-rate sample
// nearest that time (computed from i directly, never accumulated: no drift).
// Times are seconds on the audio's own clock (sample 0 at 0 s).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "arco/audio/audio_reader.h"
#include "arco/audio/pitch_hmm.h"
#include "arco/audio/yin.h"
#include "arco/registry/instruments.h"
#include "arco/util/number_range.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"

namespace arco::audio {

// Search range and analysis rate of an instrument (registry/instruments.h,
// PitchSearchRange).
struct InstrumentRange {
  std::string name;  // canonical instrument name (ParseInstrumentKind) or "any"
  double min_f0_hz = 0;
  double max_f0_hz = 0;
  int analysis_rate_hz = 0;
};
// Any name ParseInstrumentKind accepts ("violin", "viola", "cello", "double_bass" and
// the aliases, e.g. "bass"); "any" covers them all. Error for unknown names.
StatusOr<InstrumentRange> InstrumentRangeByName(const std::string& name);

// The declared ranges of PitchTrackerOptions (Validate(); `arco pitch` declares the same).
inline constexpr NumberRange kTrackerFpsRange = AboveZero(1000);
// The video may start at most an hour before the audio.
inline constexpr NumberRange kTrackerStartRangeS = Closed(-3600, 1e6);
inline constexpr NumberRange kHopsPerFrameRange = Closed(0, 100);
// Overrides of an instrument's f0 limits: 0 keeps the instrument's; else what the
// tracker can analyse: at least 20 Hz, at most the analysis rate / 4, which is 8000 Hz for
// the violin and viola (32 kHz) and 4000 Hz for the cello and double bass (16 kHz:
// PitchTrackerOptions::Validate checks the instrument's). A test checks 8000 against the
// registry.
inline constexpr NumberRange kF0OverrideRangeHz = Closed(0, 8000);

struct PitchTrackerOptions {
  InstrumentRange range;    // from InstrumentRangeByName
  double fps = 30.0;        // video frame rate, rows of the frame track
  double start_s = 0.0;     // audio time of video frame 0 (may be negative)
  int hops_per_frame = 0;   // fine rows per video frame; 0 = auto (fine rate >= 100 Hz)
  int64_t max_frames = -1;  // stop after this many video frames (-1: end of audio)
  double a4_hz = 440.0;     // reference for cents/MIDI (used by notes)
  YinOptions yin;           // rate and range are taken from `range`
  PitchHmmOptions hmm;      // range and frame rate are taken from the above
  // Readable error for absurd values (fps <= 0 or > 1000, ranges, ...).
  Status Validate() const;
};

struct PitchFrame {
  int64_t frame = 0;
  double time_s = 0;
  double f0_hz = 0;  // 0 when unvoiced
  double confidence = 0;
  bool voiced = false;
};

struct PitchTrack {
  double fps = 0;       // rate of `frames`
  double fine_fps = 0;  // rate of `fine`
  int hops_per_frame = 1;
  double start_s = 0;
  std::vector<PitchFrame> frames;  // one per video frame
  std::vector<PitchFrame> fine;    // every hop (frames[i] == fine[i * hops_per_frame])
};

struct PitchSummary {
  std::string source_format;
  int source_rate_hz = 0;
  int source_channels = 0;
  int analysis_rate_hz = 0;
  double duration_s = 0;  // decoded audio length
  int64_t frames = 0;
  double voiced_fraction = 0;           // of video frames
  double min_f0_hz = 0, max_f0_hz = 0;  // over voiced frames (0 when none)
  double cpu_seconds = 0;               // process CPU time spent (informational; not in results)
  std::vector<std::string> warnings;    // e.g. truncated file, silent audio
};

// Progress (util/progress.h) of TrackPitch: SetTotal(kPitchProgressSteps), then Advance as
// the audio is read, in thousandths of its expected duration (none when it is unknown).
inline constexpr int64_t kPitchProgressSteps = 1000;

// Tracks pitch from an open reader. Errors: decode failures mid-stream.
StatusOr<PitchTrack> TrackPitch(std::unique_ptr<AudioReader> reader,
                                const PitchTrackerOptions& options,
                                PitchSummary* summary,
                                Progress& progress = NoProgress());
// Opens `path` (OpenAudio) and tracks it.
StatusOr<PitchTrack> TrackPitchFile(const std::string& path,
                                    const PitchTrackerOptions& options,
                                    PitchSummary* summary,
                                    Progress& progress = NoProgress());

// pitch.csv: header `frame,time_s,f0_hz,confidence,voiced`, written atomically.
Status WritePitchCsv(const std::string& path, const std::vector<PitchFrame>& frames);
// The file's text (time_s to 1 us, f0_hz and confidence to 1e-4, f0_hz 0 when unvoiced).
std::string FormatPitchCsv(const std::vector<PitchFrame>& frames);
// The same with the optional second-note column (double stops, double_stops.h):
// `frame,time_s,f0_hz,confidence,voiced,f0_2_hz`, f0_2_hz to 1e-4 and 0 on frames without
// a second note; `second_f0_hz` holds one value per frame (std::invalid_argument
// otherwise). Without it (nullptr) the text is exactly the five-column one above.
std::string FormatPitchCsv(const std::vector<PitchFrame>& frames,
                           const std::vector<double>* second_f0_hz);
Status WritePitchCsv(const std::string& path,
                     const std::vector<PitchFrame>& frames,
                     const std::vector<double>* second_f0_hz);
// Reads a file written by WritePitchCsv (tests, tools).
StatusOr<std::vector<PitchFrame>> ReadPitchCsv(const std::string& path);
// The same on the file's text; `source` names it in messages. ParsePitchCsv(
// FormatPitchCsv(frames)) is what a reader of the file gets: `arco run` hands the pitch
// to the refinement that way, so that it refines what `arco refine` reads.
StatusOr<std::vector<PitchFrame>> ParsePitchCsv(const std::string& text, const std::string& source);
// The same, also reading the optional f0_2_hz column into `second_f0_hz` (one per row; all 0
// when the file has no such column).
StatusOr<std::vector<PitchFrame>> ParsePitchCsv(const std::string& text,
                                                const std::string& source,
                                                std::vector<double>* second_f0_hz);

}  // namespace arco::audio
