// arco.track_pitch: pitch of float samples at video-frame times (the rows of `arco pitch`).
#include <algorithm>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "arco/audio/audio_reader.h"
#include "arco/audio/pitch_tracker.h"
#include "arco/capture/pitch_sync.h"
#include "arco/python/bindings.h"

namespace arco::python {

// ---- pitch --------------------------------------------------------------------------

// Float samples held by the caller (the numpy array outlives the reader), (frames,) or
// interleaved (frames, channels). Mixed down as the file readers do (audio/audio_reader.h:
// the channels' float sum times 1 / channels), so a WAV's samples give `arco pitch`'s rows;
// TrackPitch refuses non-finite samples first, with the readers' check (CheckSamples).
class SamplesReader : public audio::AudioReader {
 public:
  SamplesReader(const float* samples, int64_t frames, int channels, int rate_hz)
      : samples_(samples), frames_(frames), channels_(channels) {
    info_.sample_rate_hz = rate_hz;
    info_.channels = channels;
    info_.frames = frames;
    info_.format = "float32 samples";
    info_.source = "samples";
  }
  StatusOr<int64_t> ReadMono(float* out, int64_t max_frames) override {
    const int64_t n = std::min(max_frames, frames_ - position_);
    const float scale = 1.0f / static_cast<float>(channels_);
    for (int64_t i = 0; i < n; ++i) {
      const float* frame = samples_ + (position_ + i) * channels_;
      float sum = 0.0f;
      for (int c = 0; c < channels_; ++c) sum += frame[c];
      out[i] = sum * scale;
    }
    position_ += n;
    return n;
  }

 private:
  const float* samples_;
  int64_t frames_;
  int channels_;
  int64_t position_ = 0;
};

py::dict PitchColumns(const std::vector<audio::PitchFrame>& frames) {
  const size_t n = frames.size();
  std::vector<int64_t> frame(n);
  std::vector<double> time_s(n), f0_hz(n), confidence(n);
  std::vector<uint8_t> voiced(n);
  for (size_t i = 0; i < n; ++i) {
    frame[i] = frames[i].frame;
    time_s[i] = frames[i].time_s;
    f0_hz[i] = frames[i].f0_hz;
    confidence[i] = frames[i].confidence;
    voiced[i] = frames[i].voiced;
  }
  py::dict out;
  out["frame"] = VectorToArray(std::move(frame));
  out["time_s"] = VectorToArray(std::move(time_s));
  out["f0_hz"] = VectorToArray(std::move(f0_hz));
  out["confidence"] = VectorToArray(std::move(confidence));
  out["voiced"] = VectorToArray(std::move(voiced)).attr("view")("bool");
  return out;
}

py::dict TrackPitch(const py::array_t<float, py::array::c_style | py::array::forcecast>& samples,
                    int sample_rate,
                    double fps,
                    const std::string& instrument,
                    double start_s,
                    int64_t frames,
                    int hops_per_frame,
                    double a4_hz,
                    double min_f0_hz,
                    double max_f0_hz) {
  if (samples.ndim() != 1 && samples.ndim() != 2) {
    RaiseValueError("samples must be (frames,) or (frames, channels), got " + ShapeString(samples));
  }
  const int channels = samples.ndim() == 2 ? static_cast<int>(samples.shape(1)) : 1;
  if (channels < 1 || channels > 1024) {
    RaiseValueError("samples have " + std::to_string(channels) + " channels (1..1024)");
  }
  if (sample_rate < audio::kMinRateHz || sample_rate > audio::kMaxRateHz) {
    RaiseValueError("sample_rate " + std::to_string(sample_rate) + " outside " +
                    std::to_string(audio::kMinRateHz) + ".." + std::to_string(audio::kMaxRateHz) +
                    " Hz");
  }
  // PitchRunOptions reads NaN as "the default"; here a NaN is the caller's value.
  CheckValid(CheckInRange("fps", fps, audio::kTrackerFpsRange));
  CheckValid(CheckInRange("start_s", start_s, audio::kTrackerStartRangeS));
  CheckValid(CheckInRange("a4_hz", a4_hz, kA4RangeHz));
  CheckValid(
      audio::CheckSamples(samples.data(), samples.size(), channels, 0, sample_rate, "samples"));
  capture::PitchRunOptions o;
  o.instrument = instrument;
  o.fps = fps;
  o.start_s = start_s;
  o.frames = frames;
  o.hops_per_frame = hops_per_frame;
  o.a4_hz = a4_hz;
  o.min_f0_hz = min_f0_hz;
  o.max_f0_hz = max_f0_hz;
  const StatusOr<audio::PitchTrackerOptions> tracker = capture::PitchTrackerOptionsFor(o);
  CheckValid(tracker.status());
  audio::PitchSummary summary;
  auto reader =
      std::make_unique<SamplesReader>(samples.data(), samples.shape(0), channels, sample_rate);
  StatusOr<audio::PitchTrack> track = [&] {
    py::gil_scoped_release release;
    return audio::TrackPitch(std::move(reader), *tracker, &summary);
  }();
  if (!track.ok()) throw std::runtime_error(track.status().message());
  return PitchColumns(track->frames);
}

void BindPitch(py::module_& m) {
  m.def("track_pitch",
        &TrackPitch,
        "samples"_a,
        "sample_rate"_a,
        "fps"_a = 30.0,
        "instrument"_a = "cello",
        py::kw_only(),
        "start_s"_a = 0.0,
        "frames"_a = -1,
        "hops_per_frame"_a = 0,
        "a4_hz"_a = 440.0,
        "min_f0_hz"_a = 0.0,
        "max_f0_hz"_a = 0.0,
        R"(Pitch of float samples ((frames,) or (frames, channels), mixed down as `arco pitch` does)
at video-frame times: the rows of `arco pitch`.

Returns a dict of columns frame, time_s, f0_hz (0 unvoiced), confidence, voiced.)");
}

}  // namespace arco::python
