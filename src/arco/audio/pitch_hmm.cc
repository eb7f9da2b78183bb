#include "arco/audio/pitch_hmm.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace arco::audio {
namespace {
constexpr double kNegInf = -std::numeric_limits<double>::infinity();
constexpr double kFloor = 1e-7;  // emission floor: a voiced bin with no candidate
}  // namespace

void PitchHmmOptions::Validate() const {
  auto fail = [](const std::string& m) { throw std::invalid_argument("PitchHmmOptions: " + m); };
  if (!(min_f0_hz > 0 && max_f0_hz > min_f0_hz)) fail("need 0 < min_f0_hz < max_f0_hz");
  if (!(bin_cents >= 1 && bin_cents <= 100)) fail("bin_cents must be in [1, 100]");
  if (!(frame_rate_hz > 0 && frame_rate_hz <= 10000)) fail("frame_rate_hz must be in (0, 10000]");
  if (!(max_slope_cents_per_s > 0)) fail("max_slope_cents_per_s must be positive");
  if (!(switches_per_s > 0) || !(jumps_per_s > 0)) fail("switch and jump rates must be positive");
  if (!(yin_trust > 0 && yin_trust <= 1)) fail("yin_trust must be in (0, 1]");
  if (!(lag_s >= 0 && lag_s <= 600)) fail("lag_s must be in [0, 600]");
  const double bins = 1200.0 * std::log2(max_f0_hz / min_f0_hz) / bin_cents + 1;
  if (bins * 2 > 65000) fail("too many pitch bins (range too wide for bin_cents)");
}

PitchHmm::PitchHmm(const PitchHmmOptions& options, Sink sink)
    : options_(options), sink_(std::move(sink)) {
  options.Validate();
  const auto& o = options;
  bins_ =
      static_cast<int>(std::floor(1200.0 * std::log2(o.max_f0_hz / o.min_f0_hz) / o.bin_cents)) + 1;
  states_ = 2 * bins_;
  band_ = std::max(
      1, static_cast<int>(std::ceil(o.max_slope_cents_per_s / o.frame_rate_hz / o.bin_cents)));
  band_ = std::min(band_, bins_);
  const double p_switch = std::clamp(o.switches_per_s / o.frame_rate_hz, 1e-5, 0.5);
  const double p_jump = std::clamp(o.jumps_per_s / o.frame_rate_hz, 1e-6, 0.5);
  log_stay_ = std::log(1.0 - p_switch);
  log_switch_ = std::log(p_switch);
  log_local_ = std::log(1.0 - p_jump);
  log_jump_ = std::log(p_jump / bins_);
  const double norm = static_cast<double>(band_ + 1) * (band_ + 1);
  log_band_.resize(2 * band_ + 1);
  for (int d = -band_; d <= band_; ++d) {
    log_band_[d + band_] = std::log((band_ + 1 - std::abs(d)) / norm);
  }
  score_.assign(states_, 0.0);
  next_score_.assign(states_, 0.0);
  emission_.assign(states_, 0.0);
  mass_.assign(bins_, 0.0);
  lag_frames_ = static_cast<int64_t>(std::ceil(o.lag_s * o.frame_rate_hz));
  decide_every_ = std::max<int64_t>(1, static_cast<int64_t>(std::ceil(0.5 * o.frame_rate_hz)));
  ring_ = lag_frames_ + decide_every_ + 1;
  back_.assign(static_cast<size_t>(ring_ * states_), 0);
  frames_.resize(static_cast<size_t>(ring_));
  path_.assign(static_cast<size_t>(ring_), 0);
}

double PitchHmm::BinOf(double f0_hz) const {
  return 1200.0 * std::log2(f0_hz / options_.min_f0_hz) / options_.bin_cents;
}

void PitchHmm::Push(const FrameCandidates& frame) {
  const int64_t slot = pushed_ % ring_;
  frames_[static_cast<size_t>(slot)] = frame;
  // Emissions (log).
  std::fill(mass_.begin(), mass_.end(), 0.0);
  double total = 0;
  for (int i = 0; i < frame.count; ++i) {
    const auto& c = frame.candidates[i];
    const int b = static_cast<int>(std::lround(BinOf(c.f0_hz)));
    if (b < 0 || b >= bins_) continue;
    mass_[b] += c.probability;
    total += c.probability;
  }
  const double trust = options_.yin_trust;
  const double unvoiced = std::log(std::max(kFloor, 1.0 - trust * total) / bins_);
  const double log_floor = std::log(kFloor);
  for (int b = 0; b < bins_; ++b) {
    emission_[b] = mass_[b] > 0 ? std::log(std::max(kFloor, trust * mass_[b])) : log_floor;
    emission_[bins_ + b] = unvoiced;
  }
  uint16_t* back = back_.data() + slot * states_;
  if (pushed_ == 0) {
    for (int s = 0; s < states_; ++s) {
      score_[s] = emission_[s];
      back[s] = static_cast<uint16_t>(s);
    }
  } else {
    int arg_v = 0, arg_u = bins_;
    for (int b = 1; b < bins_; ++b) {
      if (score_[b] > score_[arg_v]) arg_v = b;
      if (score_[bins_ + b] > score_[arg_u]) arg_u = bins_ + b;
    }
    const double jump_v = score_[arg_v] + log_jump_, jump_u = score_[arg_u] + log_jump_;
    for (int b = 0; b < bins_; ++b) {
      // Best predecessor inside the local band, for the voiced and unvoiced layers.
      double best_v = kNegInf, best_u = kNegInf;
      int from_v = arg_v, from_u = arg_u;
      const int lo = std::max(0, b - band_), hi = std::min(bins_ - 1, b + band_);
      for (int p = lo; p <= hi; ++p) {
        const double t = log_band_[b - p + band_];
        if (score_[p] + t > best_v) best_v = score_[p] + t, from_v = p;
        if (score_[bins_ + p] + t > best_u) best_u = score_[bins_ + p] + t, from_u = bins_ + p;
      }
      best_v += log_local_;
      best_u += log_local_;
      if (jump_v > best_v) best_v = jump_v, from_v = arg_v;
      if (jump_u > best_u) best_u = jump_u, from_u = arg_u;
      // Into V_b: stay voiced from V, or switch from U (and vice versa for U_b).
      const double v_from_v = best_v + log_stay_, v_from_u = best_u + log_switch_;
      const double u_from_u = best_u + log_stay_, u_from_v = best_v + log_switch_;
      if (v_from_v >= v_from_u) {
        next_score_[b] = v_from_v + emission_[b];
        back[b] = static_cast<uint16_t>(from_v);
      } else {
        next_score_[b] = v_from_u + emission_[b];
        back[b] = static_cast<uint16_t>(from_u);
      }
      if (u_from_u >= u_from_v) {
        next_score_[bins_ + b] = u_from_u + emission_[bins_ + b];
        back[bins_ + b] = static_cast<uint16_t>(from_u);
      } else {
        next_score_[bins_ + b] = u_from_v + emission_[bins_ + b];
        back[bins_ + b] = static_cast<uint16_t>(from_v);
      }
    }
    score_.swap(next_score_);
  }
  // Renormalise so scores stay in range over hours of frames.
  const double top = *std::max_element(score_.begin(), score_.end());
  for (double& s : score_) s -= top;
  ++pushed_;
  if (pushed_ - emitted_ >= lag_frames_ + decide_every_) {
    const int best =
        static_cast<int>(std::max_element(score_.begin(), score_.end()) - score_.begin());
    Emit(pushed_ - 1, best, pushed_ - emitted_ - lag_frames_);
  }
}

void PitchHmm::Finish() {
  if (pushed_ == emitted_) return;
  const int best =
      static_cast<int>(std::max_element(score_.begin(), score_.end()) - score_.begin());
  Emit(pushed_ - 1, best, pushed_ - emitted_);
}

void PitchHmm::Emit(int64_t newest, int state, int64_t count) {
  int s = state;
  for (int64_t f = newest; f >= emitted_; --f) {
    path_[static_cast<size_t>(f % ring_)] = s;
    s = back_[static_cast<size_t>((f % ring_) * states_ + s)];
  }
  for (int64_t i = 0; i < count; ++i) {
    const int64_t f = emitted_ + i;
    sink_(Decode(f, path_[static_cast<size_t>(f % ring_)]));
  }
  emitted_ += count;
}

DecodedFrame PitchHmm::Decode(int64_t index, int state) const {
  const FrameCandidates& frame = frames_[static_cast<size_t>(index % ring_)];
  DecodedFrame out;
  out.index = index;
  if (state >= bins_) {
    out.confidence = frame.total_probability();
    return out;
  }
  // The frame's own candidate closest to the decoded bin gives the f0.
  int best = -1;
  double best_distance = 1.5;  // bins
  for (int i = 0; i < frame.count; ++i) {
    const double distance = std::abs(BinOf(frame.candidates[i].f0_hz) - state);
    if (distance < best_distance) best_distance = distance, best = i;
  }
  out.voiced = true;
  out.f0_hz = best >= 0 ? frame.candidates[best].f0_hz
                        : options_.min_f0_hz * std::exp2(state * options_.bin_cents / 1200.0);
  const double near_bins = 50.0 / options_.bin_cents;
  for (int i = 0; i < frame.count; ++i) {
    if (std::abs(BinOf(frame.candidates[i].f0_hz) - BinOf(out.f0_hz)) <= near_bins) {
      out.confidence += frame.candidates[i].probability;
    }
  }
  out.confidence = std::min(1.0, out.confidence);
  return out;
}

}  // namespace arco::audio
