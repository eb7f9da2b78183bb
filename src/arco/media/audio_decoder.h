// Decoding the audio stream of any container FFmpeg reads (the sound track of a video,
// mp3, aac, ...), for audio/'s readers: media/ is the one owner of FFmpeg's libavformat
// and libavcodec, and this header keeps them out of every layer above.
//
//   ARCO_ASSIGN_OR_RETURN(auto decoder, media::AudioDecoder::Open("cam0.mp4"));
//   std::vector<float> block;
//   while (true) {
//     ARCO_ASSIGN_OR_RETURN(bool more, decoder->Decode(&block));
//     if (!more) break;
//     ...  // block: the next mono samples at decoder->info().sample_rate_hz
//   }
//
// The best audio stream is decoded on one thread (deterministic) and libswresample only
// averages its channels into mono float at the stream's own rate: rate conversion is
// audio/'s (resampler.h), so timing is exact and the same for every input. Index 0 is the
// first decoded sample (container start offsets are ignored). A corrupt packet is
// skipped, as players do, until 100 decode errors. Errors are Status messages that begin
// with the file name.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "arco/util/status.h"

namespace arco::media {

struct AudioStreamInfo {
  int sample_rate_hz = 0;
  int channels = 0;
  // Samples the stream's duration promises at its rate; -1 when the container does not
  // say.
  int64_t frames = -1;
  std::string codec;  // decoder name: "aac", "pcm_s16le", "flac", ...
};

class AudioDecoder {
 public:
  // Errors: the file cannot be opened or probed, has no audio stream, or no decoder for
  // it. The rate and channel count are reported, not checked (the caller's limits).
  static StatusOr<std::unique_ptr<AudioDecoder>> Open(const std::string& path);
  ~AudioDecoder();
  AudioDecoder(const AudioDecoder&) = delete;
  AudioDecoder& operator=(const AudioDecoder&) = delete;

  const AudioStreamInfo& info() const { return info_; }
  // Replaces `mono` with the next decoded frame's samples (possibly none); false at the
  // end of the stream. Errors: persistent decode errors, a rate or channel count that
  // changes mid-stream, a failed sample conversion.
  StatusOr<bool> Decode(std::vector<float>* mono);

 private:
  struct State;
  AudioDecoder(const std::string& path, std::unique_ptr<State> state);

  std::string path_;
  AudioStreamInfo info_;
  std::unique_ptr<State> state_;
};

// For a video file: the time (s) of its first video frame on the clock whose zero is
// the first decoded sample of its audio track (the stream start times of the container;
// an audio start before 0, an encoder's priming that the decoder drops, counts as 0).
// 0 for files without both streams.
StatusOr<double> VideoStartOnAudioClock(const std::string& path);

}  // namespace arco::media
