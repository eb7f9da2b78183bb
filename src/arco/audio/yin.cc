#include "arco/audio/yin.h"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <mutex>
#include <stdexcept>
#include <string>

namespace arco::audio {
namespace {

// FFTW's planner is not thread-safe; plans are made once per analyzer.
std::mutex& PlannerMutex() {
  static std::mutex mutex;
  return mutex;
}

// Smallest n >= target of the form 2^a 3^b 5^c (fast FFTW sizes).
int FastFftSize(int target) {
  int best = 1;
  while (best < target) best *= 2;
  for (int p5 = 1; p5 <= best; p5 *= 5) {
    for (int p35 = p5; p35 <= best; p35 *= 3) {
      int n = p35;
      while (n < target) n *= 2;
      best = std::min(best, n);
    }
  }
  return best;
}

// Beta(alpha, beta) density, unnormalised.
double BetaPdf(double x, double alpha, double beta) {
  return std::pow(x, alpha - 1.0) * std::pow(1.0 - x, beta - 1.0);
}

}  // namespace

YinAnalyzer::YinAnalyzer(const YinOptions& options) : options_(options) {
  const auto& o = options;
  if (o.sample_rate_hz < 1000 || o.sample_rate_hz > 384000) {
    throw std::invalid_argument("YinOptions: sample_rate_hz must be in [1000, 384000]");
  }
  if (!(o.min_f0_hz >= 10.0) || !(o.max_f0_hz > o.min_f0_hz) ||
      !(o.max_f0_hz <= o.sample_rate_hz / 4.0)) {
    throw std::invalid_argument("YinOptions: need 10 <= min_f0_hz < max_f0_hz <= rate/4, got " +
                                std::to_string(o.min_f0_hz) + ".." + std::to_string(o.max_f0_hz));
  }
  if (!(o.window_periods >= 1.5 && o.window_periods <= 8.0)) {
    throw std::invalid_argument("YinOptions: window_periods must be in [1.5, 8]");
  }
  if (!(o.threshold_prior_mean > 0.01 && o.threshold_prior_mean < 0.5)) {
    throw std::invalid_argument("YinOptions: threshold_prior_mean must be in (0.01, 0.5)");
  }
  if (!(o.subharmonic_ratio >= 0.0 && o.subharmonic_ratio <= 1.0)) {
    throw std::invalid_argument("YinOptions: subharmonic_ratio must be in [0, 1]");
  }
  if (!(o.submultiple_probability >= 0.0 && o.submultiple_probability <= 0.1)) {
    throw std::invalid_argument("YinOptions: submultiple_probability must be in [0, 0.1]");
  }
  const double fs = o.sample_rate_hz;
  min_lag_ = std::max(2, static_cast<int>(std::floor(fs / o.max_f0_hz)));
  max_lag_ = static_cast<int>(std::ceil(fs / o.min_f0_hz)) + 1;
  window_ = static_cast<int>(std::ceil(o.window_periods * fs / o.min_f0_hz));
  window_ = std::max(window_, max_lag_ + 4);
  // Linear (not circular) autocorrelation up to max_lag needs N >= W + max_lag.
  fft_size_ = FastFftSize(window_ + max_lag_ + 1);
  silence_rms_ = std::pow(10.0, o.silence_rms_dbfs / 20.0);

  // pYIN threshold distribution: Beta(2, beta) with the requested mean on the
  // thresholds 0.01, 0.02, ..., 1.00.
  const double alpha = 2.0;
  const double beta = alpha * (1.0 - o.threshold_prior_mean) / o.threshold_prior_mean;
  threshold_cdf_.assign(101, 0.0);
  double total = 0;
  for (int i = 1; i <= 100; ++i) {
    const double s = std::min(i / 100.0, 0.9999);
    total += BetaPdf(s, alpha, beta);
    threshold_cdf_[i] = total;
  }
  for (double& c : threshold_cdf_) c /= total;

  const int n = fft_size_;
  power_.assign(n / 2 + 1, 0.0);
  prefix_energy_.assign(window_ + 1, 0.0);
  diff_.assign(max_lag_ + 2, 0.0);
  cmndf_.assign(max_lag_ + 2, 1.0);
  minima_.reserve(max_lag_);
  minima_prob_.reserve(max_lag_);
  minima_value_.reserve(max_lag_);
  minima_submultiple_.reserve(max_lag_);
  std::lock_guard<std::mutex> lock(PlannerMutex());
  time_ = fftw_alloc_real(n);
  auto* spectrum = fftw_alloc_complex(n / 2 + 1);
  spectrum_ = spectrum;
  // FFTW_ESTIMATE: the plan (hence every bit of the result) does not depend on
  // timing measurements, so output is deterministic run to run.
  forward_plan_ = fftw_plan_dft_r2c_1d(n, time_, spectrum, FFTW_ESTIMATE);
  inverse_plan_ = fftw_plan_dft_c2r_1d(n, spectrum, time_, FFTW_ESTIMATE);
}

YinAnalyzer::~YinAnalyzer() {
  std::lock_guard<std::mutex> lock(PlannerMutex());
  fftw_destroy_plan(static_cast<fftw_plan>(forward_plan_));
  fftw_destroy_plan(static_cast<fftw_plan>(inverse_plan_));
  fftw_free(time_);
  fftw_free(spectrum_);
}

void YinAnalyzer::Analyze(const float* window, FrameCandidates* out) {
  const int w = window_, n = fft_size_;
  out->count = 0;
  double mean = 0;
  for (int j = 0; j < w; ++j) mean += window[j];
  mean /= w;
  double energy = 0;
  prefix_energy_[0] = 0;
  for (int j = 0; j < w; ++j) {
    const double v = window[j] - mean;
    time_[j] = v;
    energy += v * v;
    prefix_energy_[j + 1] = energy;
  }
  std::fill(time_ + w, time_ + n, 0.0);
  const double rms = std::sqrt(energy / w);
  out->rms_dbfs = rms > 1e-10 ? 20.0 * std::log10(rms) : -200.0;
  std::fill(cmndf_.begin(), cmndf_.end(), 1.0);
  if (rms < silence_rms_) return;

  // Autocorrelation r(tau) = IFFT(|X|^2) (unnormalised FFTW: divide by N).
  fftw_execute(static_cast<fftw_plan>(forward_plan_));
  auto* spectrum = static_cast<fftw_complex*>(spectrum_);
  for (int k = 0; k <= n / 2; ++k) {
    const double p = spectrum[k][0] * spectrum[k][0] + spectrum[k][1] * spectrum[k][1];
    spectrum[k][0] = p;
    spectrum[k][1] = 0;
    const double fold = (k == 0 || 2 * k == n) ? 1.0 : 2.0;
    power_[k] = fold * p / n;
  }
  fftw_execute(static_cast<fftw_plan>(inverse_plan_));

  // Eq. 6 (type II window, per-pair mean) and Eq. 8 (cumulative mean normalisation).
  const double total = prefix_energy_[w];
  double running = 0;
  diff_[0] = 0;
  cmndf_[0] = 1;
  for (int tau = 1; tau <= max_lag_; ++tau) {
    const double m = prefix_energy_[w - tau] + (total - prefix_energy_[tau]);
    const double r = time_[tau] / n;
    const double d = std::max(0.0, (m - 2.0 * r) / (w - tau));
    diff_[tau] = d;
    running += d;
    cmndf_[tau] = running > 0 ? d * tau / running : 1.0;
  }

  // Dips of d' inside the lag range, shortest lag first.
  minima_.clear();
  minima_prob_.clear();
  minima_value_.clear();
  minima_submultiple_.clear();
  int global = -1;
  for (int tau = std::max(min_lag_, 2); tau < max_lag_; ++tau) {
    if (cmndf_[tau] < cmndf_[tau - 1] && cmndf_[tau] <= cmndf_[tau + 1]) {
      // Depth of the dip at its parabolic vertex: at short lags the integer
      // lag can sit far up the dip's wall, which would make a true period look
      // worse than its sub-harmonic (octave-down errors on high notes).
      const double a = cmndf_[tau - 1], b = cmndf_[tau], c = cmndf_[tau + 1];
      const double curvature = a - 2.0 * b + c;
      const double vertex = curvature > 0 ? b - (a - c) * (a - c) / (8.0 * curvature) : b;
      minima_.push_back(tau);
      minima_value_.push_back(std::clamp(vertex, 0.0, b));
      minima_prob_.push_back(0.0);
      minima_submultiple_.push_back(0);
      if (global < 0 || minima_value_.back() < minima_value_[global]) {
        global = static_cast<int>(minima_.size()) - 1;
      }
    }
  }
  if (minima_.empty()) return;
  // Threshold s picks the first dip whose value is below s, so dip k takes the
  // prior mass of s in (d'_k, min over earlier dips].
  auto cdf = [&](double x) {
    const int i = std::clamp(static_cast<int>(std::floor(x * 100.0 + 1e-9)), 0, 100);
    return threshold_cdf_[i];
  };
  double earlier_min = 1e9;
  for (size_t k = 0; k < minima_.size(); ++k) {
    const double v = minima_value_[k];
    if (v < earlier_min) {
      minima_prob_[k] = cdf(std::min(earlier_min, 1.0)) - cdf(v);
      earlier_min = v;
    }
  }
  // Thresholds below every dip: pYIN gives 1% of their mass to the global minimum.
  minima_prob_[global] += 0.01 * cdf(minima_value_[global]);

  // Sub-harmonic check: mass at lag tau moves to a dip near 2*tau or 3*tau that
  // is much deeper (then tau was a harmonic, not the period).
  if (options_.subharmonic_ratio > 0) {
    for (size_t k = 0; k < minima_.size(); ++k) {
      if (minima_prob_[k] <= 0) continue;
      const double v = minima_value_[k];
      for (int mult = 2; mult <= 3; ++mult) {
        const double target = static_cast<double>(minima_[k]) * mult;
        const double tolerance = std::max(2.0, 0.03 * target);
        int best = -1;
        for (size_t q = k + 1; q < minima_.size(); ++q) {
          if (std::abs(minima_[q] - target) <= tolerance &&
              (best < 0 || minima_value_[q] < minima_value_[best])) {
            best = static_cast<int>(q);
          }
        }
        if (best >= 0) {
          const double vb = minima_value_[best];
          if (vb < options_.subharmonic_ratio * v && v - vb > 0.03) {
            minima_prob_[best] += minima_prob_[k];
            minima_prob_[k] = 0;
            break;
          }
        }
      }
    }
  }

  // Sub-multiple candidates (YinOptions::submultiple_probability): the deepest
  // dip near 2x / 3x the lag of each threshold candidate that has no mass of
  // its own gets a small one (not refined by Newton steps: it is a fallback
  // for the HMM, and the parabolic lag is good to a few cents at these long
  // lags). Marked negative until the pass ends, so a sub-multiple does not
  // spawn its own (6x, 9x).
  const double submultiple = options_.submultiple_probability;
  if (submultiple > 0) {
    const size_t found = minima_.size();
    for (size_t k = 0; k < found; ++k) {
      if (!(minima_prob_[k] > 0)) continue;
      for (int mult = 2; mult <= 3; ++mult) {
        const double target = static_cast<double>(minima_[k]) * mult;
        const double tolerance = std::max(2.0, 0.03 * target);
        int best = -1;
        for (size_t q = k + 1; q < found; ++q) {
          if (std::abs(minima_[q] - target) <= tolerance &&
              (best < 0 || minima_value_[q] < minima_value_[best])) {
            best = static_cast<int>(q);
          }
        }
        if (best >= 0 && minima_prob_[best] == 0 && minima_value_[best] < 1.0) {
          minima_prob_[best] = -submultiple * (1.0 - minima_value_[best]);
          minima_submultiple_[best] = 1;
        }
      }
    }
    for (double& p : minima_prob_) p = std::abs(p);
  }

  // Keep the most probable dips, refine their lags, store as f0 candidates.
  for (int slot = 0; slot < kMaxPitchCandidates; ++slot) {
    int best = -1;
    for (size_t k = 0; k < minima_.size(); ++k) {
      if (minima_prob_[k] > 1e-6 && (best < 0 || minima_prob_[k] > minima_prob_[best])) {
        best = static_cast<int>(k);
      }
    }
    if (best < 0) break;
    // Newton refinement costs O(N); weak candidates keep a parabolic estimate.
    const bool refine = minima_prob_[best] >= 0.02 && !minima_submultiple_[best];
    const double lag = refine ? RefineLag(minima_[best]) : ParabolicLag(minima_[best]);
    PitchCandidate& c = out->candidates[out->count++];
    c.f0_hz = options_.sample_rate_hz / lag;
    c.probability = minima_prob_[best];
    c.cmndf = minima_value_[best];
    minima_prob_[best] = 0;
  }
}

double YinAnalyzer::ParabolicLag(int lag) const {
  const double a = diff_[lag - 1], b = diff_[lag], c = diff_[lag + 1];
  const double den = a - 2.0 * b + c;
  return den > 0 ? lag + std::clamp(0.5 * (a - c) / den, -0.5, 0.5) : lag;
}

// Newton steps on f(tau) = (m(tau) - 2 r(tau)) / (W - tau) at fractional tau:
// r from the power spectrum (r(tau) = sum_k P_k cos(2 pi k tau / N), exact
// band-limited interpolation), m(tau) linear between integer lags.
double YinAnalyzer::RefineLag(int lag) const {
  const int w = window_, n = fft_size_, half = n / 2;
  const double total = prefix_energy_[w];
  auto energy_at = [&](int i) { return prefix_energy_[w - i] + (total - prefix_energy_[i]); };
  double tau = lag;
  for (int iteration = 0; iteration < 3; ++iteration) {
    const std::complex<double> step = std::polar(1.0, 2.0 * M_PI * tau / n);
    std::complex<double> z(1.0, 0.0);
    double r = 0, r1 = 0, r2 = 0;
    for (int k = 0; k <= half; ++k) {
      const double p = power_[k], pk = p * k;
      r += p * z.real();
      r1 -= pk * z.imag();
      r2 -= pk * k * z.real();
      z *= step;
    }
    const double omega = 2.0 * M_PI / n;
    r1 *= omega;
    r2 *= omega * omega;
    const int i = std::clamp(static_cast<int>(std::floor(tau)), 1, max_lag_ - 1);
    const double frac = tau - i;
    const double m0 = energy_at(i), m1 = energy_at(i + 1);
    const double m = m0 + frac * (m1 - m0);
    const double g = m - 2.0 * r, g1 = (m1 - m0) - 2.0 * r1, g2 = -2.0 * r2;
    const double l = w - tau;
    const double f1 = g1 / l + g / (l * l);
    const double f2 = g2 / l + 2.0 * g1 / (l * l) + 2.0 * g / (l * l * l);
    if (!(f2 > 0)) break;
    const double delta = std::clamp(-f1 / f2, -0.5, 0.5);
    tau = std::clamp(tau + delta, lag - 1.0, lag + 1.0);
    if (std::abs(delta) < 1e-4) break;
  }
  return tau;
}

}  // namespace arco::audio
