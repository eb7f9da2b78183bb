#include "arco/audio/sample_stream.h"

#include <algorithm>
#include <stdexcept>

namespace arco::audio {
namespace {
constexpr int64_t kBlock = 8192;
}

SampleStream::SampleStream(std::unique_ptr<AudioReader> reader, int analysis_rate_hz)
    : reader_(std::move(reader)),
      resampler_(reader_->info().sample_rate_hz, analysis_rate_hz),
      block_in_(kBlock),
      block_out_(kBlock) {}

Status SampleStream::DecodeBlock() {
  // Drain what the resampler can give, then feed it one more block.
  while (true) {
    const int64_t got = resampler_.Pull(block_out_.data(), kBlock);
    if (got > 0) {
      buffer_.insert(buffer_.end(), block_out_.begin(), block_out_.begin() + got);
      return Status::Ok();
    }
    if (source_done_) {
      finished_ = true;
      return Status::Ok();
    }
    auto n = reader_->ReadMono(block_in_.data(), kBlock);
    if (!n.ok()) return n.status();
    if (*n == 0) {
      source_done_ = true;
      resampler_.Finish();
    } else {
      source_samples_ += *n;
      resampler_.Push(block_in_.data(), *n);
    }
  }
}

StatusOr<bool> SampleStream::Has(int64_t index) {
  if (index < 0) return false;
  while (index >= decoded() && !finished_) ARCO_RETURN_IF_ERROR(DecodeBlock());
  return index < decoded();
}

Status SampleStream::Read(int64_t start, int length, float* out) {
  if (start < last_start_) throw std::invalid_argument("SampleStream::Read: start went backwards");
  last_start_ = start;
  const int64_t end = start + length;
  while (end > decoded() && !finished_) ARCO_RETURN_IF_ERROR(DecodeBlock());
  // Forget samples before `start`; compact only when it frees a lot (amortised).
  const int64_t drop = std::min<int64_t>(start - base_, static_cast<int64_t>(buffer_.size()));
  if (drop > kBlock && drop * 2 > static_cast<int64_t>(buffer_.size())) {
    buffer_.erase(buffer_.begin(), buffer_.begin() + drop);
    base_ += drop;
  }
  for (int i = 0; i < length; ++i) {
    const int64_t k = start + i - base_;
    out[i] = (k >= 0 && k < static_cast<int64_t>(buffer_.size())) ? buffer_[static_cast<size_t>(k)]
                                                                  : 0.0f;
  }
  return Status::Ok();
}

}  // namespace arco::audio
