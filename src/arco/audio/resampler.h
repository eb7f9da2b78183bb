// Streaming band-limited sample-rate conversion with exact timing.
//
// Output sample n is the band-limited value of the input at time n / output_rate
// (input sample m is at m / input_rate): with L/M = output/input in lowest terms,
// output n sits at input position n*M/L, computed in integers, so no drift
// accumulates however long the stream. Filter: Kaiser-windowed sinc (beta 8.6,
// 16 zero crossings of the lower rate, cutoff 0.92 of the lower Nyquist).
// Coefficients are tabulated per phase at set-up (L phases when L <= 4096, else
// 4096 phases with linear interpolation between them); Push/Pull do not allocate
// once the internal buffer has grown to the largest block pushed.
#pragma once

#include <cstdint>
#include <vector>

namespace arco::audio {

class Resampler {
 public:
  // Throws std::invalid_argument for rates <= 0.
  Resampler(int input_rate_hz, int output_rate_hz);

  int input_rate_hz() const { return input_rate_hz_; }
  int output_rate_hz() const { return output_rate_hz_; }

  // Appends input samples.
  void Push(const float* input, int64_t count);
  // Marks the end of the input (zeros follow); after this Pull drains the rest.
  void Finish();
  // Writes up to max_count output samples whose filter support is available;
  // returns how many were written (0: push more, or all done after Finish).
  int64_t Pull(float* output, int64_t max_count);
  // True once Finish was called and every output sample was pulled. The number
  // of output samples is ceil(inputs * output_rate / input_rate).
  bool done() const;

 private:
  double Coefficient(int64_t phase_numerator, int tap) const;

  int input_rate_hz_, output_rate_hz_;
  int64_t up_ = 1, down_ = 1;  // L, M
  bool identity_ = false;
  int taps_ = 1;          // K, even
  int table_phases_ = 1;  // rows in table_
  bool interpolate_phases_ = false;
  std::vector<float> table_;  // table_phases_(+1) x taps_
  std::vector<float> input_;  // input samples from absolute index input_base_
  int64_t input_base_ = 0;
  int64_t input_count_ = 0;  // absolute number of samples pushed
  int64_t next_output_ = 0;
  bool finished_ = false;
};

}  // namespace arco::audio
