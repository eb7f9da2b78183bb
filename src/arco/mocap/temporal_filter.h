// NaN-aware temporal filtering of keypoint trajectories.
//
// A trajectory is split at NaN. Gaps of at most `max_gap_frames` frames are first
// filled by linear interpolation between their neighbours; longer gaps (and the
// ends) stay NaN and separate segments that are filtered independently, so a
// missing stretch never smears into its neighbours. Filters:
//  - Butterworth low-pass, zero phase: the order-N digital filter (bilinear transform
//    with prewarping, second-order sections) run forward and backward with odd-
//    extension padding and steady-state initial conditions (as scipy.signal.filtfilt);
//    the effective magnitude response is |H|^2 (-6 dB at the cutoff).
//  - Savitzky-Golay (Savitzky & Golay 1964): least-squares polynomial of `polyorder`
//    over an odd `window`; the first and last half-windows are evaluated on the
//    polynomial fitted to the first / last full window (no shift, no padding). A
//    segment shorter than the window uses the largest odd window that fits.
//  - One-euro (Casiez, Roussel & Vogel, CHI 2012): adaptive first-order low-pass,
//    causal (it lags); cutoff = min_cutoff_hz + beta * |speed|, with the speed in
//    units per second.
#pragma once

#include <string>
#include <vector>

#include "arco/util/npy.h"
#include "arco/util/status.h"

namespace arco {

enum class FilterKind { kNone, kButterworth, kSavitzkyGolay, kOneEuro };

struct TemporalFilterOptions {
  FilterKind kind = FilterKind::kNone;
  int max_gap_frames = 5;      // NaN gaps up to this length are filled; 0 fills none
  double cutoff_hz = 6.0;      // Butterworth cutoff
  int order = 4;               // Butterworth order (1..8)
  int window = 9;              // Savitzky-Golay window, odd, frames
  int polyorder = 2;           // Savitzky-Golay polynomial order (< window)
  double min_cutoff_hz = 1.0;  // one-euro
  double beta = 0.0;           // one-euro speed coefficient (1 / units)
  double d_cutoff_hz = 1.0;    // one-euro cutoff for the speed estimate
  // `fps` is the frame rate the filter will run at (cutoffs must stay below fps/2).
  Status Validate(double fps) const;
};

// Parses "none", "butterworth[:CUTOFF_HZ[:ORDER]]", "savgol[:WINDOW[:POLYORDER]]",
// "oneeuro[:MIN_CUTOFF_HZ[:BETA[:D_CUTOFF_HZ]]]"; omitted values keep the defaults.
StatusOr<TemporalFilterOptions> ParseFilterSpec(const std::string& spec);
std::string FilterSpecToString(const TemporalFilterOptions& options);

// Filters one trajectory in place (NaN = missing), sampled at `fps`.
// Throws std::invalid_argument when options.Validate(fps) fails.
void FilterTrajectory(const TemporalFilterOptions& options, double fps, std::vector<double>* x);

// Fills NaN gaps of at most `max_gap_frames` by linear interpolation (interior gaps only).
void FillShortGaps(int max_gap_frames, std::vector<double>* x);

// Filters the chosen keypoints of a (F, P, 3) array; each coordinate separately.
void FilterPoints(const TemporalFilterOptions& options,
                  double fps,
                  const std::vector<int>& point_indices,
                  NpyArray<double>* points3d);

}  // namespace arco
