#include "arco/audio/sync.h"

#include <algorithm>
#include <cstdlib>
#include <utility>

#include "arco/audio/audio_reader.h"
#include "arco/audio/sample_stream.h"
#include "arco/media/video_reader.h"

namespace arco::audio {
namespace {

constexpr int kRate = 16000;
constexpr int kFrame = 32;    // 2 ms onset frames
constexpr int kHistory = 25;  // 50 ms of previous frames
constexpr int kGrayWidth = 160;

// [lo, hi) frame indices of the search window around `near_s` (all when NaN).
void Window(
    double near_s, double search_s, double frames_per_s, int64_t count, int64_t* lo, int64_t* hi) {
  *lo = 0;
  *hi = count;
  if (!std::isnan(near_s)) {
    *lo = std::clamp<int64_t>(
        static_cast<int64_t>(std::floor((near_s - search_s) * frames_per_s)), 0, count);
    *hi = std::clamp<int64_t>(
        static_cast<int64_t>(std::ceil((near_s + search_s) * frames_per_s)) + 1, 0, count);
  }
}

// Strongest value in [lo, hi) and the strongest more than `apart` frames away.
void PeakAndRunnerUp(const std::vector<double>& v,
                     int64_t lo,
                     int64_t hi,
                     int64_t apart,
                     int64_t* best,
                     double* runner_up) {
  *best = -1;
  for (int64_t k = lo; k < hi; ++k) {
    if (*best < 0 || v[k] > v[*best]) *best = k;
  }
  *runner_up = 0;
  for (int64_t k = lo; k < hi && *best >= 0; ++k) {
    if (std::abs(k - *best) > apart) *runner_up = std::max(*runner_up, v[k]);
  }
}

}  // namespace

Status SyncOptions::Validate() const {
  if (!(video_fps >= 0 && video_fps <= 1000)) return Status::Error("video_fps must be in [0, 1000]");
  if (!(search_s > 0 && search_s <= 3600)) return Status::Error("search_s must be in (0, 3600]");
  if (!(max_seconds > 0)) return Status::Error("max_seconds must be positive");
  return Status::Ok();
}

StatusOr<SyncEvent> FindAudioOnset(const std::string& path, const SyncOptions& options) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  std::vector<double> strength;
  {
    ARCO_ASSIGN_OR_RETURN(auto reader, OpenAudio(path));
    SampleStream stream(std::move(reader), kRate);
    std::vector<float> block(kFrame + 1);
    double history[kHistory] = {0};
    const int64_t max_frames = static_cast<int64_t>(options.max_seconds * kRate / kFrame);
    for (int64_t k = 0; k < max_frames; ++k) {
      ARCO_ASSIGN_OR_RETURN(const bool more, stream.Has(k * kFrame));
      if (!more) break;
      ARCO_RETURN_IF_ERROR(stream.Read(k * kFrame - 1, kFrame + 1, block.data()));
      double energy = 0;
      for (int i = 1; i <= kFrame; ++i) {
        const double d = block[i] - block[i - 1];
        energy += d * d;
      }
      double before = 0;
      for (double h : history) before += h;
      before /= kHistory;
      const double eps = 1e-12 * kFrame;
      strength.push_back(k < kHistory ? 0.0 : 10.0 * std::log10((energy + eps) / (before + eps)));
      history[k % kHistory] = energy;
    }
  }
  if (strength.empty()) return Status::Error(path + ": no audio samples");
  int64_t lo, hi, best;
  Window(options.audio_near_s,
         options.search_s,
         double(kRate) / kFrame,
         static_cast<int64_t>(strength.size()),
         &lo,
         &hi);
  SyncEvent event;
  PeakAndRunnerUp(strength, lo, hi, kRate / kFrame / 2, &best, &event.runner_up);
  if (best < 0) return Status::Error(path + ": the search window holds no audio");
  event.strength = strength[best];
  // Refine to the first sample of the burst (second pass over a short window).
  ARCO_ASSIGN_OR_RETURN(auto reader, OpenAudio(path));
  SampleStream stream(std::move(reader), kRate);
  const int64_t start = (best - 2) * kFrame;
  std::vector<float> x(static_cast<size_t>(8 * kFrame + 1));
  ARCO_RETURN_IF_ERROR(stream.Read(start - 1, static_cast<int>(x.size()), x.data()));
  double peak = 0;
  for (size_t i = 1; i < x.size(); ++i) peak = std::max(peak, double(std::abs(x[i] - x[i - 1])));
  size_t first = 1;
  while (first + 1 < x.size() && std::abs(x[first] - x[first - 1]) < 0.25 * peak) ++first;
  event.time_s = static_cast<double>(start + static_cast<int64_t>(first) - 1) / kRate;
  return event;
}

StatusOr<MotionEnergy> ComputeMotionEnergy(const std::string& path, double max_seconds) {
  media::VideoReaderOptions options;
  options.format = media::PixelFormat::kGray8;
  options.max_width = kGrayWidth;
  ARCO_ASSIGN_OR_RETURN(media::VideoReader reader, media::VideoReader::Open(path, options));
  MotionEnergy out;
  out.fps = reader.properties().fps_hz;
  const int64_t max_frames =
      out.fps > 0 ? static_cast<int64_t>(max_seconds * out.fps) + 1 : static_cast<int64_t>(1e6);
  media::Image gray, previous;
  while (static_cast<int64_t>(out.energy.size()) < max_frames) {
    // A frame that cannot be decoded ends the signal (an undecodable tail): the
    // event is searched in the frames before it.
    const StatusOr<bool> more = reader.Read(&gray);
    if (!more.ok() || !*more) break;
    double e = 0;
    if (!previous.empty()) {
      for (size_t i = 0; i < gray.pixels.size(); ++i) {
        e += std::abs(int(gray.pixels[i]) - int(previous.pixels[i]));
      }
      e /= static_cast<double>(gray.pixels.size());
    }
    out.energy.push_back(e);
    std::swap(previous, gray);
  }
  if (out.energy.empty()) return Status::Error(path + ": no decodable video frames");
  return out;
}

StatusOr<SyncEvent> FindVideoEvent(const std::string& path,
                                   const SyncOptions& options,
                                   double* fps_out) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  ARCO_ASSIGN_OR_RETURN(const MotionEnergy motion, ComputeMotionEnergy(path, options.max_seconds));
  const double fps = options.video_fps > 0 ? options.video_fps : motion.fps;
  if (!(fps > 0)) return Status::Error(path + ": unknown frame rate; set video_fps");
  if (fps_out != nullptr) *fps_out = fps;
  const auto& e = motion.energy;
  const int64_t n = static_cast<int64_t>(e.size());
  if (n < 3) return Status::Error(path + ": too few video frames to find an event");
  int64_t lo, hi, best;
  SyncEvent event;
  Window(options.video_near_s, options.search_s, fps, n, &lo, &hi);
  lo = std::max<int64_t>(lo, 1);
  PeakAndRunnerUp(e, lo, hi, static_cast<int64_t>(std::ceil(0.5 * fps)), &best, &event.runner_up);
  if (best < 0) return Status::Error(path + ": the search window holds no video frames");
  // A flash switches on and off (two equal bursts): take the earliest burst
  // within 80% of the strongest, then its local peak.
  for (int64_t j = lo; j < best; ++j) {
    if (e[j] >= 0.8 * e[best]) {
      while (j + 1 < hi && e[j + 1] > e[j]) ++j;
      best = j;
      break;
    }
  }
  // Background motion: the lower quartile of the window's energies.
  std::vector<double> window(e.begin() + lo, e.begin() + hi);
  std::nth_element(window.begin(), window.begin() + window.size() / 4, window.end());
  const double base = window[window.size() / 4];
  double sum = 0, weighted = 0;
  for (int64_t j = std::max<int64_t>(1, best - 1); j <= std::min(n - 1, best + 1); ++j) {
    const double w = std::max(0.0, e[j] - base);
    sum += w;
    weighted += w * j;
  }
  const double centroid = sum > 0 ? weighted / sum : static_cast<double>(best);
  event.time_s = (centroid - 0.5) / fps;
  if (options.video_event == VideoEvent::kClap && e[best] > base) {
    // The last frame of the burst still at (nearly) full motion.
    const double full = e[best];
    while (best + 1 < hi && e[best + 1] >= 0.9 * full) ++best;
    // Motion left after the peak, in units of the peak frame's motion.
    double left = 0;
    for (int64_t j = best + 1; j < std::min(n, best + 4); ++j) {
      const double w = std::max(0.0, e[j] - base);
      if (w < 0.05 * (e[best] - base)) break;
      left += w;
    }
    event.time_s = (best + left / (e[best] - base)) / fps;
    event.strength = e[best];
  }
  event.strength = e[best];
  event.frame = std::lround(event.time_s * fps);
  return event;
}

StatusOr<SyncResult> SyncAudioToVideo(const std::string& audio_path,
                                      const std::string& video_path,
                                      const SyncOptions& options) {
  SyncResult result;
  ARCO_ASSIGN_OR_RETURN(result.audio, FindAudioOnset(audio_path, options));
  ARCO_ASSIGN_OR_RETURN(result.video, FindVideoEvent(video_path, options, &result.video_fps));
  result.offset_s = result.audio.time_s - result.video.time_s;
  if (result.audio.strength < 10.0) {
    result.warnings.push_back("the audio onset is weak (< 10 dB above the preceding 50 ms)");
  }
  if (result.audio.runner_up > result.audio.strength - 3.0) {
    result.warnings.push_back("another audio onset is nearly as strong: set audio_near_s");
  }
  if (result.video.runner_up > 0.7 * result.video.strength) {
    result.warnings.push_back("other motion is nearly as strong: set video_near_s");
  }
  return result;
}

}  // namespace arco::audio
