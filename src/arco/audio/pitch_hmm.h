// pYIN stage 2: an HMM over pitch bins x {voiced, unvoiced}, decoded with a
// streaming fixed-lag Viterbi (Mauch & Dixon 2014, Sec. 2.2, with two changes:
// a small "jump anywhere" term so large legato intervals need not crawl through
// the local transition band, and fixed-lag decoding so memory does not grow with
// the recording length).
//
// States: V_b and U_b for bins b = 0..B-1, bin b centred at
// min_f0_hz * 2^(b * bin_cents / 1200). Unvoiced states keep a pitch memory, as
// in pYIN. Transitions from state (v, b) to (v', b'):
//   P = [v == v' ? 1 - p_switch : p_switch] * [(1 - p_jump) T(b' - b) + p_jump / B]
// with T triangular over |b' - b| <= max_step_bins. Emissions: V_b gets
// trust * (probability of the candidates in bin b) (floored), U_b gets
// (1 - trust * total candidate probability) / B.
// The decoded voiced bin is refined to the frame's own candidate in that bin
// (sub-cent f0), so bins only need to be fine enough to separate candidates.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "arco/audio/yin.h"

namespace arco::audio {

struct PitchHmmOptions {
  double min_f0_hz = 60.0;
  double max_f0_hz = 2000.0;
  double bin_cents = 20.0;
  double frame_rate_hz = 120.0;         // rate of Push() calls
  double max_slope_cents_per_s = 4000;  // local band: steepest smooth glide per frame
  double switches_per_s = 1.5;          // voicing changes expected per second (prior)
  double jumps_per_s = 1.0;             // large pitch jumps expected per second (prior)
  double yin_trust = 0.5;               // pYIN's trust in the YIN probabilities
  double lag_s = 2.0;                   // decisions are final this long after a frame
  // Throws std::invalid_argument with a readable message.
  void Validate() const;
};

struct DecodedFrame {
  int64_t index = 0;  // Push() order
  bool voiced = false;
  double f0_hz = 0;       // 0 when unvoiced
  double confidence = 0;  // candidate probability near f0 (voiced) or total (unvoiced)
};

class PitchHmm {
 public:
  using Sink = std::function<void(const DecodedFrame&)>;
  // Allocates all state and the lag buffer. Frames reach `sink` in order.
  PitchHmm(const PitchHmmOptions& options, Sink sink);

  void Push(const FrameCandidates& frame);
  // Decodes and emits every remaining frame.
  void Finish();
  int num_bins() const { return bins_; }

 private:
  double BinOf(double f0_hz) const;
  void Emit(int64_t newest, int best_state, int64_t count);
  DecodedFrame Decode(int64_t frame, int state) const;

  PitchHmmOptions options_;
  Sink sink_;
  int bins_ = 0, states_ = 0, band_ = 0;
  double log_stay_ = 0, log_switch_ = 0, log_local_ = 0, log_jump_ = 0;
  std::vector<double> log_band_;  // log T(delta), delta = -band..band
  std::vector<double> score_, next_score_, emission_;
  std::vector<double> mass_;             // candidate probability per bin
  int64_t ring_ = 0;                     // frames kept in the ring buffer
  std::vector<uint16_t> back_;           // ring_ x states_ back-pointers
  std::vector<FrameCandidates> frames_;  // ring_ frames
  std::vector<int> path_;                // ring_ decoded states (scratch)
  int64_t pushed_ = 0, emitted_ = 0, lag_frames_ = 0, decide_every_ = 0;
};

}  // namespace arco::audio
