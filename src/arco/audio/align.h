// Aligning two recordings of the same sound by their audio (`arco capture new --sync
// audio`): two cameras' tracks, or a camera's track and a separate recorder.
//
// Clock model: a time t_other on the other recording's clock (its first decoded sample
// at 0) is the time
//   t_ref = offset_s + (1 + drift_ppm * 1e-6) * t_other
// on the reference's clock. offset_s is where the other recording starts on the
// reference's clock (positive: it started later); drift_ppm > 0 when the other device's
// clock runs slow (its second lasts longer than the reference's).
//
// Method: GCC-PHAT (Knapp & Carter 1976, "The generalized correlation method for
// estimation of time delay"): the cross-spectrum whitened to unit magnitude, so every
// frequency votes equally and the correlation peak is sharp for music and noise alike.
//  1. Global lag: GCC-PHAT of the whole recordings at kAlignCoarseRateHz. The
//     runner-up (the largest value more than exclusion_s from the winner) measures
//     ambiguity: a periodic signal (a metronome), or two unrelated recordings, give a
//     runner-up close to the winner, which is an error carrying both lags.
//  2. Local lags: GCC-PHAT of windows spread over the overlap at fine_rate_hz, each
//     searched within margin_s of the global lag, refined below a sample by a parabola
//     through the peak and its neighbours. Silent or unclear windows are left out.
//  3. offset_s and drift_ppm: a least-squares line through the local lags against the
//     window centres (drift only over a span of at least min_drift_span_s; shorter, the
//     drift is 0 and offset_s the lags' mean), one pass dropping windows more than
//     outlier_s from the line.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "arco/util/status.h"

namespace arco::audio {

// The rate of the global search (Hz); windows use AlignOptions::fine_rate_hz.
inline constexpr int kAlignCoarseRateHz = 4000;
// A recording whose RMS level is below this (dBFS) is silent: nothing to align.
inline constexpr double kAlignSilentDbfs = -60.0;

struct AlignOptions {
  int fine_rate_hz = 16000;        // rate of the local lags (sub-sample refined)
  double max_seconds = 900.0;      // decode at most this much of each recording
  double max_lag_s = 0;            // |offset_s| at most this (0: any overlap)
  double window_s = 4.0;           // local-lag window length
  int max_windows = 24;            // spread evenly over the overlap
  double max_drift_ppm = 300.0;    // clock drift the windows' search allows for
  double min_drift_span_s = 20.0;  // shorter spans estimate no drift
  double ambiguous_ratio = 0.7;    // runner-up / winner above this: ambiguous
  double outlier_s = 0.001;        // a window farther from the line is dropped
  Status Validate() const;
};

// Mono samples of a recording at `rate_hz` (decoded, downmixed, resampled).
struct AudioTrack {
  std::string source;
  int rate_hz = 0;
  std::vector<float> samples;
  double duration_s() const { return rate_hz > 0 ? double(samples.size()) / rate_hz : 0; }
};

// Decodes the first max_seconds of `path` (its best audio stream: a video's track or
// an audio file) at `rate_hz`. Errors name the file: no audio stream, undecodable.
StatusOr<AudioTrack> LoadAudioTrack(const std::string& path, int rate_hz, double max_seconds);

// RMS level of a track, dBFS (below kAlignSilentDbfs: silent).
double TrackLevelDbfs(const AudioTrack& track);

struct AlignResult {
  double offset_s = 0;         // see the clock model above
  double drift_ppm = 0;        // 0 when the span was too short to measure it
  double confidence = 0;       // 0..1: 1 - runner-up / winner of the global correlation
  double runner_up_lag_s = 0;  // where the runner-up was (reference minus other)
  int windows = 0;             // local windows tried
  int windows_used = 0;        // ... that agreed with the line
  double residual_rms_s = 0;   // of the used windows' lags about the line
  double span_s = 0;           // between the first and last used window centres
};

// Aligns `other` to `reference` (both at options.fine_rate_hz). Errors (naming the
// sources): silent track, no overlap, an ambiguous correlation, no window with a clear
// peak, a drift beyond max_drift_ppm.
StatusOr<AlignResult> AlignTracks(const AudioTrack& reference,
                                  const AudioTrack& other,
                                  const AlignOptions& options);

}  // namespace arco::audio
