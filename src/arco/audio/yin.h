// Per-frame pitch candidates after probabilistic YIN (pYIN stage 1).
//
// References: de Cheveigne & Kawahara, "YIN, a fundamental frequency estimator
// for speech and music", JASA 2002 (difference function, Eq. 6; cumulative mean
// normalised difference, Eq. 8); Mauch & Dixon, "pYIN: a fundamental frequency
// estimator using probabilistic threshold distributions", ICASSP 2014 (a Beta
// prior over the YIN threshold turns one estimate into candidates with
// probabilities).
//
// Differences from textbook YIN, and why:
// - The difference function is taken over one window of W samples centred on the
//   analysis time: d(tau) = sum_{j=0}^{W-1-tau} (x_j - x_{j+tau})^2 / (W - tau)
//   ("type II" windowing, as in McLeod's MPM). The pairs of every lag are centred
//   on the window centre, so pitch is timed exactly at the frame time for every
//   lag (textbook YIN shifts by up to tau_max / 2).
// - d is computed with one real FFT pair (autocorrelation) plus prefix sums of
//   x^2; the window mean is removed first, which leaves d unchanged (a DC offset
//   cancels in x_j - x_{j+tau}) and keeps the FFT well conditioned.
// - Sub-sample lag: Newton steps on d(tau) evaluated at fractional lags from the
//   power spectrum (band-limited interpolation of the autocorrelation), which
//   keeps errors well under one cent where parabolic interpolation of YIN's
//   Eq. 8 is off by several cents for short periods.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace arco::audio {

struct YinOptions {
  int sample_rate_hz = 16000;
  double min_f0_hz = 60.0;
  double max_f0_hz = 2000.0;
  // Window length in periods of min_f0_hz (2: the longest lag still pairs one
  // full period).
  double window_periods = 2.0;
  // Mean of the Beta prior over thresholds (pYIN uses 0.1, 0.15 or 0.2).
  double threshold_prior_mean = 0.15;
  // Frames whose RMS (after removing the mean) is below this are silent.
  double silence_rms_dbfs = -60.0;
  // Lower candidates win unless a candidate at 2x or 3x the lag is this much
  // better in CMNDF (pure-YIN's first-dip rule makes octave-up errors on low
  // notes whose fundamental is weak in the recording).
  double subharmonic_ratio = 0.2;
  // Sub-multiple candidates: the deepest dip near 2x and 3x the lag of each
  // candidate gets this prior mass (times 1 - d') when the threshold rule gave
  // it none. pYIN's first-dip rule leaves a low note no candidate at all in
  // frames where its 2nd or 3rd harmonic briefly dominates (bow changes,
  // re-attacks), and the HMM then leaves the note for the harmonic and comes
  // back (two jumps, 2 ln(p_jump / bins) ~ -20 at 100 Hz). With mass m on the
  // note, staying costs about ln(1 / m) = 3 per frame instead, so a harmonic
  // that dominates for up to ~50-70 ms no longer pulls the track off the note,
  // while a longer one (a real note) still does. 0.05: the smallest value that
  // keeps FluidR3's viola and bass re-attacks (40-80 ms) on the note.
  double submultiple_probability = 0.05;
};

struct PitchCandidate {
  double f0_hz = 0;
  double probability = 0;  // pYIN threshold probability, sums to <= 1 per frame
  double cmndf = 1;        // YIN's d'(tau) at the dip (0: perfectly periodic)
};

constexpr int kMaxPitchCandidates = 8;

struct FrameCandidates {
  std::array<PitchCandidate, kMaxPitchCandidates> candidates;
  int count = 0;
  double rms_dbfs = -200;  // level of the window (after mean removal)
  double total_probability() const {
    double s = 0;
    for (int i = 0; i < count; ++i) s += candidates[i].probability;
    return s;
  }
};

class YinAnalyzer {
 public:
  // Validates (std::invalid_argument) and allocates FFT plans and buffers.
  explicit YinAnalyzer(const YinOptions& options);
  ~YinAnalyzer();
  YinAnalyzer(const YinAnalyzer&) = delete;
  YinAnalyzer& operator=(const YinAnalyzer&) = delete;

  // Samples per analysis window; the window starts at centre - window_length()/2.
  int window_length() const { return window_; }
  const YinOptions& options() const { return options_; }

  // Candidates for one window of window_length() samples. Does not allocate.
  void Analyze(const float* window, FrameCandidates* out);

  // The CMNDF d'(tau) of the last Analyze call, for tau in [0, max_lag()].
  const std::vector<double>& cmndf() const { return cmndf_; }
  int min_lag() const { return min_lag_; }
  int max_lag() const { return max_lag_; }

 private:
  double RefineLag(int lag) const;
  double ParabolicLag(int lag) const;

  YinOptions options_;
  int window_ = 0, fft_size_ = 0, min_lag_ = 0, max_lag_ = 0;
  double silence_rms_ = 0;
  std::vector<double> threshold_cdf_;  // P(threshold <= i/100), i = 0..100
  double* time_ = nullptr;             // fftw buffers
  void* spectrum_ = nullptr;
  void* forward_plan_ = nullptr;
  void* inverse_plan_ = nullptr;
  std::vector<double> power_;          // |X_k|^2 / N, k = 0..N/2
  std::vector<double> prefix_energy_;  // sum_{j<i} x_j^2
  std::vector<double> diff_, cmndf_;
  std::vector<int> minima_;
  std::vector<double> minima_prob_;
  std::vector<double> minima_value_;      // d' at the dip's parabolic vertex
  std::vector<char> minima_submultiple_;  // mass from the sub-multiple rule only
};

}  // namespace arco::audio
