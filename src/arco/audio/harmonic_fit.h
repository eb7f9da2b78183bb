// Pitch of one analysis window from the frequencies of its harmonic peaks: a
// slow, precise, offline measurement (no difference function, no
// autocorrelation), used where a pitch reference must not depend on arco's
// tracker: the sound-corrected truth of the pitch benchmark (sound_truth.h) and
// the soundfont tuning of `arco synth` (synth/audio_render.cc).
#pragma once

#include <vector>

namespace arco::audio {

// f0 of one window by fitting the frequencies of its harmonic peaks.
// Method: mean removed, Hann window, FFT zero-padded to >= 8x the window; for
// harmonics h = 1..16 below 0.45 fs, the largest magnitude bin within +-S cents
// of h * f, refined by a parabola through the log magnitudes of it and its two
// neighbours (f_h, amplitude A_h); harmonics weaker than 1% of the strongest
// are dropped; f0 = sum(A_h^2 h f_h) / sum(A_h^2 h^2) (least squares of
// f_h = h f0 with weights A_h^2, the inverse variance of a peak's frequency).
// Two passes: f = nominal with S = 100 cents over h <= 6 (so neighbouring
// harmonics cannot fall inside the search band), then f = that estimate with
// S = 30 cents over all harmonics.
class HarmonicPeakFit {
 public:
  HarmonicPeakFit(int sample_rate_hz, int max_window);
  ~HarmonicPeakFit();
  HarmonicPeakFit(const HarmonicPeakFit&) = delete;
  HarmonicPeakFit& operator=(const HarmonicPeakFit&) = delete;

  // f0 in Hz of x[0..n) (n <= max_window) near nominal_hz; NaN when the window
  // is silent (RMS below -60 dBFS) or has no peak near the fundamental series.
  double F0Hz(const float* x, int n, double nominal_hz);

 private:
  double Pass(double f_hz, double search_cents, int max_harmonic) const;

  int rate_ = 0, fft_size_ = 0;
  double* time_ = nullptr;
  void* spectrum_ = nullptr;
  void* plan_ = nullptr;
  std::vector<double> log_magnitude_;
};

// Window used for a key: 6 periods of its nominal f0, at least 30 ms (long
// enough to resolve the harmonics with a Hann window, short enough to follow a
// sample's own 5 Hz, +-35 cent vibrato within about 1 cent: the window mean of
// a sinusoid is attenuated by sinc(f T), 1 - (pi f T)^2 / 6 = 0.96 at 30 ms).
int HarmonicFitWindow(int sample_rate_hz, double nominal_hz);

}  // namespace arco::audio
