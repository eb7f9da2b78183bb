#include "arco/audio/resampler.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace arco::audio {
namespace {

constexpr int kZeroCrossings = 16;
constexpr double kCutoff = 0.92;     // fraction of the lower Nyquist frequency
constexpr double kKaiserBeta = 8.6;  // about -90 dB side lobes
constexpr int64_t kMaxTablePhases = 4096;

// Zeroth-order modified Bessel function of the first kind (power series).
double BesselI0(double x) {
  double sum = 1.0, term = 1.0;
  for (int k = 1; k < 60; ++k) {
    term *= (x / (2.0 * k)) * (x / (2.0 * k));
    sum += term;
    if (term < 1e-17 * sum) break;
  }
  return sum;
}

}  // namespace

Resampler::Resampler(int input_rate_hz, int output_rate_hz)
    : input_rate_hz_(input_rate_hz), output_rate_hz_(output_rate_hz) {
  if (input_rate_hz <= 0 || output_rate_hz <= 0) {
    throw std::invalid_argument("Resampler: sample rates must be positive");
  }
  const int64_t g = std::gcd<int64_t>(input_rate_hz, output_rate_hz);
  up_ = output_rate_hz / g;
  down_ = input_rate_hz / g;
  identity_ = (up_ == 1 && down_ == 1);
  if (identity_) return;
  // Filter support in input samples: kZeroCrossings zero crossings of the lower rate.
  const double ratio = std::max(1.0, static_cast<double>(down_) / static_cast<double>(up_));
  taps_ = 2 * static_cast<int>(std::ceil(kZeroCrossings * ratio));
  taps_ = (taps_ + 7) / 8 * 8;  // the dot product runs 8 lanes; extra taps are zero
  // At most ~4M coefficients (16 MB) whatever the ratio.
  const int64_t max_phases =
      std::max<int64_t>(64, std::min<int64_t>(kMaxTablePhases, (1 << 22) / taps_));
  interpolate_phases_ = up_ > max_phases;
  table_phases_ = static_cast<int>(interpolate_phases_ ? max_phases : up_);
  const int rows = table_phases_ + (interpolate_phases_ ? 1 : 0);
  table_.resize(static_cast<size_t>(rows) * taps_);
  // Normalised cutoff in cycles per input sample, and the half-width of support.
  const double fc = 0.5 * kCutoff / ratio;
  const double half_width = taps_ / 2.0;
  const double i0_beta = BesselI0(kKaiserBeta);
  for (int row = 0; row < rows; ++row) {
    const double frac = static_cast<double>(row) / table_phases_;  // position in [0, 1]
    for (int k = 0; k < taps_; ++k) {
      // Tap k multiplies input p - taps/2 + 1 + k, at distance v from the output.
      const double v = frac + (taps_ / 2 - 1 - k);
      const double x = 2.0 * fc * v;
      const double sinc = std::abs(x) < 1e-12 ? 1.0 : std::sin(M_PI * x) / (M_PI * x);
      const double r = v / half_width;
      const double window =
          std::abs(r) >= 1.0 ? 0.0 : BesselI0(kKaiserBeta * std::sqrt(1.0 - r * r)) / i0_beta;
      table_[static_cast<size_t>(row) * taps_ + k] = static_cast<float>(2.0 * fc * sinc * window);
    }
  }
  // Samples before the start are zeros: pre-fill the history.
  input_.assign(static_cast<size_t>(taps_), 0.0f);
  input_base_ = -taps_;
}

void Resampler::Push(const float* input, int64_t count) {
  if (count <= 0) return;
  if (identity_) {
    input_.insert(input_.end(), input, input + count);
    input_count_ += count;
    return;
  }
  // Drop history no longer needed by the next output (keeps memory bounded).
  const int64_t next_base = (next_output_ * down_) / up_ - taps_ / 2 + 1;
  const int64_t drop =
      std::min<int64_t>(next_base - input_base_, static_cast<int64_t>(input_.size()));
  if (drop > 4096 && drop * 2 > static_cast<int64_t>(input_.size())) {
    input_.erase(input_.begin(), input_.begin() + drop);
    input_base_ += drop;
  }
  input_.insert(input_.end(), input, input + count);
  input_count_ += count;
}

void Resampler::Finish() {
  if (finished_) return;
  finished_ = true;
  if (!identity_) input_.insert(input_.end(), static_cast<size_t>(taps_), 0.0f);
}

bool Resampler::done() const {
  if (!finished_) return false;
  if (identity_) return next_output_ >= input_count_;
  // ceil(input_count * L / M) outputs in total.
  const int64_t total = (input_count_ * up_ + down_ - 1) / down_;
  return next_output_ >= total;
}

int64_t Resampler::Pull(float* output, int64_t max_count) {
  if (identity_) {
    const int64_t available = input_count_ - next_output_;
    const int64_t n = std::min(available, max_count);
    if (n <= 0) return 0;
    std::copy_n(input_.begin(), n, output);
    input_.erase(input_.begin(), input_.begin() + n);
    next_output_ += n;
    return n;
  }
  const int64_t total = finished_ ? (input_count_ * up_ + down_ - 1) / down_ : INT64_MAX;
  const int64_t available_end = input_base_ + static_cast<int64_t>(input_.size());
  int64_t written = 0;
  while (written < max_count && next_output_ < total) {
    const int64_t numerator = next_output_ * down_;  // exact input position * L
    const int64_t p = numerator / up_;
    const int64_t phase = numerator % up_;
    const int64_t first = p - taps_ / 2 + 1;
    if (first + taps_ > available_end) break;  // need more input
    const float* x = input_.data() + (first - input_base_);
    float acc = 0.0f;
    if (!interpolate_phases_) {
      // Eight independent partial sums in a fixed order: vectorisable and
      // deterministic (no reassociation left to the compiler).
      const float* h = table_.data() + static_cast<size_t>(phase) * taps_;
      float lane[8] = {0, 0, 0, 0, 0, 0, 0, 0};
      for (int k = 0; k < taps_; k += 8) {
        for (int l = 0; l < 8; ++l) lane[l] += x[k + l] * h[k + l];
      }
      acc =
          ((lane[0] + lane[4]) + (lane[1] + lane[5])) + ((lane[2] + lane[6]) + (lane[3] + lane[7]));
    } else {
      const double pos = static_cast<double>(phase) * table_phases_ / static_cast<double>(up_);
      const int row = std::min(static_cast<int>(pos), table_phases_ - 1);
      const double w1 = pos - row;
      const float* h0 = table_.data() + static_cast<size_t>(row) * taps_;
      const float* h1 = h0 + taps_;
      for (int k = 0; k < taps_; ++k) {
        acc += static_cast<float>(x[k] * ((1.0 - w1) * h0[k] + w1 * h1[k]));
      }
    }
    output[written++] = acc;
    ++next_output_;
  }
  return written;
}

}  // namespace arco::audio
