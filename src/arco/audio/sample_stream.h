// A forward-only window onto a decoded, downmixed and resampled stream: the
// pitch tracker asks for windows [start, start + length) at the analysis rate
// with non-decreasing starts; samples before 0 and after the end read as zero.
// Only the samples still needed are kept (an hour of audio is never in memory).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "arco/audio/audio_reader.h"
#include "arco/audio/resampler.h"
#include "arco/util/status.h"

namespace arco::audio {

class SampleStream {
 public:
  SampleStream(std::unique_ptr<AudioReader> reader, int analysis_rate_hz);

  int rate_hz() const { return resampler_.output_rate_hz(); }
  const AudioInfo& source_info() const { return reader_->info(); }

  // Decodes until sample `index` exists or the stream ends; true if it exists.
  StatusOr<bool> Has(int64_t index);
  // Copies [start, start + length) into out (zeros outside the stream).
  // `start` must not decrease between calls (std::invalid_argument otherwise).
  Status Read(int64_t start, int length, float* out);

  bool finished() const { return finished_; }
  // Samples decoded so far at the analysis rate (the total once finished()).
  int64_t decoded() const { return base_ + static_cast<int64_t>(buffer_.size()); }
  // Samples read from the source at its own rate.
  int64_t source_samples() const { return source_samples_; }

 private:
  Status DecodeBlock();

  std::unique_ptr<AudioReader> reader_;
  Resampler resampler_;
  std::vector<float> block_in_, block_out_;
  std::vector<float> buffer_;  // samples [base_, base_ + size)
  int64_t base_ = 0;
  int64_t last_start_ = INT64_MIN;
  int64_t source_samples_ = 0;
  bool source_done_ = false;
  bool finished_ = false;
};

}  // namespace arco::audio
