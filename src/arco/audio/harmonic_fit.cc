#include "arco/audio/harmonic_fit.h"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace arco::audio {
namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace

int HarmonicFitWindow(int sample_rate_hz, double nominal_hz) {
  return static_cast<int>(std::lround(sample_rate_hz * std::max(0.03, 6.0 / nominal_hz)));
}

HarmonicPeakFit::HarmonicPeakFit(int sample_rate_hz, int max_window) : rate_(sample_rate_hz) {
  if (sample_rate_hz < 1000 || max_window < 16) {
    throw std::invalid_argument("HarmonicPeakFit: bad sample rate or window");
  }
  fft_size_ = 1;
  while (fft_size_ < 8 * max_window) fft_size_ *= 2;
  time_ = fftw_alloc_real(fft_size_);
  auto* spectrum = fftw_alloc_complex(fft_size_ / 2 + 1);
  spectrum_ = spectrum;
  plan_ = fftw_plan_dft_r2c_1d(fft_size_, time_, spectrum, FFTW_ESTIMATE);
  log_magnitude_.assign(fft_size_ / 2 + 1, 0.0);
}

HarmonicPeakFit::~HarmonicPeakFit() {
  fftw_destroy_plan(static_cast<fftw_plan>(plan_));
  fftw_free(time_);
  fftw_free(spectrum_);
}

double HarmonicPeakFit::F0Hz(const float* x, int n, double nominal_hz) {
  if (n * 8 > fft_size_ || n < 16) throw std::invalid_argument("HarmonicPeakFit: window size");
  double mean = 0;
  for (int j = 0; j < n; ++j) mean += x[j];
  mean /= n;
  double energy = 0;
  for (int j = 0; j < n; ++j) {
    const double v = x[j] - mean;
    energy += v * v;
    const double s = std::sin(M_PI * (j + 0.5) / n);  // Hann
    time_[j] = v * s * s;
  }
  std::fill(time_ + n, time_ + fft_size_, 0.0);
  if (std::sqrt(energy / n) < 1e-3) return kNaN;  // -60 dBFS
  fftw_execute(static_cast<fftw_plan>(plan_));
  const auto* spectrum = static_cast<const fftw_complex*>(spectrum_);
  for (int k = 0; k <= fft_size_ / 2; ++k) {
    const double p = spectrum[k][0] * spectrum[k][0] + spectrum[k][1] * spectrum[k][1];
    log_magnitude_[k] = 0.5 * std::log(p + 1e-300);
  }
  const double first = Pass(nominal_hz, 100.0, 6);
  if (!std::isfinite(first)) return kNaN;
  return Pass(first, 30.0, 16);
}

double HarmonicPeakFit::Pass(double f_hz, double search_cents, int max_harmonic) const {
  const double bin_hz = static_cast<double>(rate_) / fft_size_;
  const double spread = std::exp2(search_cents / 1200.0);
  std::vector<double> freq, amp;
  std::vector<int> harmonic;
  for (int h = 1; h <= max_harmonic; ++h) {
    const double hi_hz = h * f_hz * spread;
    if (hi_hz > 0.45 * rate_) break;
    const int lo = std::max(1, static_cast<int>(std::floor(h * f_hz / spread / bin_hz)));
    const int hi = static_cast<int>(std::ceil(hi_hz / bin_hz));
    int best = lo;
    for (int k = lo; k <= hi; ++k) {
      if (log_magnitude_[k] > log_magnitude_[best]) best = k;
    }
    if (best == lo || best == hi) continue;  // no peak inside the band
    const double a = log_magnitude_[best - 1], b = log_magnitude_[best],
                 c = log_magnitude_[best + 1];
    const double den = a - 2.0 * b + c;
    if (!(den < 0)) continue;
    const double delta = 0.5 * (a - c) / den;  // vertex of the parabola, |delta| <= 0.5
    freq.push_back((best + delta) * bin_hz);
    amp.push_back(std::exp(b - 0.25 * (a - c) * delta));
    harmonic.push_back(h);
  }
  if (freq.empty()) return kNaN;
  const double strongest = *std::max_element(amp.begin(), amp.end());
  double num = 0, den = 0;
  bool has_low = false;
  for (size_t i = 0; i < freq.size(); ++i) {
    if (amp[i] < 0.01 * strongest) continue;
    const double w = amp[i] * amp[i], h = harmonic[i];
    num += w * h * freq[i];
    den += w * h * h;
    has_low = has_low || harmonic[i] <= 3;
  }
  return den > 0 && has_low ? num / den : kNaN;
}

}  // namespace arco::audio
