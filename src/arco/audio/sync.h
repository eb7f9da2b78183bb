// Automatic audio/video synchronisation from one sharp event (a hand clap, a
// slate, a flash): the event in the audio and the same event in one or more videos,
// each timed below a frame, give
//   offset_s = audio_event_s - video_event_s,
// so that audio_time = video_time + offset_s: video frame i sits at audio time
// offset_s + i / fps, which is exactly `arco pitch --start-s` (or --offset-s).
// No event, or two comparable candidates, is an error whose message carries the
// evidence; every result carries a confidence (docs/audio.md, "Sync").
//
// Audio onset strength (per 2 ms frame): log energy of the first difference
// (emphasises broadband clicks) minus the log of the mean energy of the previous
// 50 ms; the winning frame is refined to the first sample whose |difference|
// exceeds a quarter of the burst's peak.
// Video motion energy: frames read with media::VideoReader, scaled to 160 px wide
// grayscale; E[j] = mean |g_j - g_{j-1}|. Frame j's timestamp j / fps is taken
// as the middle of its exposure (so pitch row j, centred at offset + j / fps,
// matches what frame j shows).
// Flash (VideoEvent::kFlash): a step in brightness at t inside frame k's exposure
// [(k - 1/2)/fps, (k + 1/2)/fps) with a fully open shutter gives E[k] : E[k+1] =
// (1 - phi) : phi where t = (k - 1/2 + phi)/fps, so the event time is (c - 1/2)/fps
// with c the E-weighted centroid around the strongest brightening.
// Clap (VideoEvent::kClap, the default): the sound happens at contact, when the
// moving hands stop, so the event is the end of a burst of motion: the frame K where
// motion energy drops sharply (largest drop from the 2 frames up to K to the frames
// 3-4 after it). Hands moving at speed v that stop at t inside frame K + 1 leave
// sum_{k>K} (E[k] - A) = (1/2 + phi) (E[K] - A) after the last fully moving frame K
// (A: the energy once they rest), so t = (K + sum_{k>K} (E[k] - A) / (E[K] - A)) / fps,
// exact for hands at constant speed whichever fully moving frame is taken as K.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "arco/util/status.h"

namespace arco::audio {

enum class VideoEvent { kClap, kFlash };

// Decision thresholds, defined once (docs/audio.md, "Sync").
// An audio onset needs this much energy (dB) over the preceding 50 ms.
inline constexpr double kSyncMinOnsetDb = 10.0;
// ... and its peak (over the 50 ms from the onset) this much over the recording's
// median level: a clap stands out of the room and the music, a bow change does not.
inline constexpr double kSyncMinAboveFloorDb = 10.0;
// A video event (a drop of motion energy for a clap, a rise for a flash) needs this
// many times the frame-to-frame jitter of the motion energy, and at least
// kSyncMinMotionGrey grey levels.
inline constexpr double kSyncMinMotionSnr = 6.0;
inline constexpr double kSyncMinMotionGrey = 0.05;
// Candidates this close (s) are one event (a clap's echo, a flash's two frames).
inline constexpr double kSyncSameEventS = 0.5;
// A signal is ambiguous when its runner-up reaches this fraction of the winner
// (amplitude ratio for audio: 3.1 dB; motion energy change for video).
inline constexpr double kSyncAmbiguousRatio = 0.7;
// Below this confidence the result carries a warning.
inline constexpr double kSyncLowConfidence = 0.5;

struct SyncOptions {
  VideoEvent video_event = VideoEvent::kClap;  // how the video event is timed
  double video_fps = 0;                        // 0: the stream's average frame rate
  double audio_near_s = NAN;   // look for the audio event near this time (NaN: anywhere)
  double video_near_s = NAN;   // likewise for the video (seconds of video time)
  double search_s = 3.0;       // half-width of the windows above
  double max_seconds = 600.0;  // scan at most this much of each file
  Status Validate() const;
};

struct SyncEvent {
  double time_s = 0;  // on the file's own clock
  // Audio: onset strength (dB over the preceding 50 ms). Video: the size of the clap's
  // drop (or the flash's rise) of motion energy, grey levels.
  double strength = 0;
  double runner_up = 0;           // the strongest candidate more than 0.5 s away
  double runner_up_time_s = NAN;  // where it is (NaN: none)
  double level = 0;  // audio: peak level near the event, dBFS; video: peak motion energy
  double floor = 0;  // audio: median frame level, dBFS; video: background motion energy
  double noise = 0;  // video: frame-to-frame jitter of the motion energy (grey levels)
  // 0..1: how clearly the winner beats the runner-up (audio: 1 - amplitude ratio,
  // video: 1 - strength ratio).
  double distinctness = 0;
  int64_t frame = -1;  // video: the frame whose exposure holds the event
};

// One video of a synchronised rig. `global_frame` maps a (fractional) 0-based frame
// index of this video to the rig's common frame numbering (a capture's global frames,
// where a camera's dropped frames are skipped); empty: the index itself.
struct SyncView {
  std::string video;
  std::function<double(double video_frame)> global_frame;
};

struct SyncViewResult {
  std::string video;
  double fps = 0;
  SyncEvent event;            // on this video's own clock (valid when error is empty)
  double global_frame = NAN;  // the event on the common frame numbering
  bool used = false;          // agrees with the consensus and counts in the offset
  std::string error;          // why this view has no event (it is then left out)
};

struct SyncResult {
  // audio_time = offset_s + g / fps for common frame g (for one video without a
  // mapping: audio_time = video_time + offset_s).
  double offset_s = 0;
  double video_fps = 0;
  double confidence = 0;              // 0..1 (docs/audio.md, "Sync")
  SyncEvent audio, video;             // video: the first view that counts
  double event_global_frame = 0;      // the consensus of the views' events
  std::vector<SyncViewResult> views;  // one per video, in order
  std::vector<std::string> warnings;  // low confidence, views left out
};

StatusOr<SyncEvent> FindAudioOnset(const std::string& audio_path, const SyncOptions& options);

// Motion energy (E[0] = 0) and mean grey level per video frame, and the stream's rate.
struct MotionEnergy {
  double fps = 0;
  std::vector<double> energy;
  std::vector<double> mean_grey;
};
StatusOr<MotionEnergy> ComputeMotionEnergy(const std::string& video_path, double max_seconds);
// The event in a motion energy signal at `fps` (`source` names it in errors).
StatusOr<SyncEvent> FindVideoEventInEnergy(const MotionEnergy& motion,
                                           double fps,
                                           const SyncOptions& options,
                                           const std::string& source);
StatusOr<SyncEvent> FindVideoEvent(const std::string& video_path,
                                   const SyncOptions& options,
                                   double* fps_out);

// The audio event and each view's event; the views that agree (within half a frame
// of their median) give the offset. Views without a clear event are left out with a
// warning while at least one has one.
StatusOr<SyncResult> SyncAudioToVideos(const std::string& audio_path,
                                       const std::vector<SyncView>& views,
                                       const SyncOptions& options);
StatusOr<SyncResult> SyncAudioToVideo(const std::string& audio_path,
                                      const std::string& video_path,
                                      const SyncOptions& options);

}  // namespace arco::audio
