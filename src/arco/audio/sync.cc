#include "arco/audio/sync.h"

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <utility>

#include "arco/audio/audio_reader.h"
#include "arco/audio/sample_stream.h"
#include "arco/media/video_reader.h"
#include "arco/util/number_range.h"

namespace arco::audio {
namespace {

constexpr int kRate = 16000;
constexpr int kFrame = 32;    // 2 ms onset frames
constexpr int kHistory = 25;  // 50 ms of previous frames
constexpr int kGrayWidth = 160;

std::string Format(const char* format, ...) __attribute__((format(printf, 1, 2)));
std::string Format(const char* format, ...) {
  char buffer[768];
  va_list args;
  va_start(args, format);
  std::vsnprintf(buffer, sizeof(buffer), format, args);
  va_end(args);
  return buffer;
}

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

// Strongest value in [lo, hi) and the strongest more than `apart` frames away
// (runner_at = -1 when there is none).
void PeakAndRunnerUp(const std::vector<double>& v,
                     int64_t lo,
                     int64_t hi,
                     int64_t apart,
                     int64_t* best,
                     int64_t* runner_at) {
  *best = -1;
  *runner_at = -1;
  for (int64_t k = lo; k < hi; ++k) {
    if (*best < 0 || v[k] > v[*best]) *best = k;
  }
  for (int64_t k = lo; k < hi && *best >= 0; ++k) {
    if (std::abs(k - *best) > apart && (*runner_at < 0 || v[k] > v[*runner_at])) *runner_at = k;
  }
}

// The q-quantile (0..1) of v[lo, hi).
double Quantile(const std::vector<double>& v, int64_t lo, int64_t hi, double q) {
  std::vector<double> w(v.begin() + lo, v.begin() + hi);
  if (w.empty()) return 0;
  const size_t at = std::min(w.size() - 1, static_cast<size_t>(q * static_cast<double>(w.size())));
  std::nth_element(w.begin(), w.begin() + static_cast<std::ptrdiff_t>(at), w.end());
  return w[at];
}

// Frame-to-frame jitter of v over [lo, hi): a robust standard deviation of its steps.
double Jitter(const std::vector<double>& v, int64_t lo, int64_t hi) {
  std::vector<double> steps;
  for (int64_t j = lo + 1; j < hi; ++j) steps.push_back(std::abs(v[j] - v[j - 1]));
  if (steps.empty()) return 0;
  return 1.4826 * Quantile(steps, 0, static_cast<int64_t>(steps.size()), 0.5);
}

// The video event's evidence, for error messages.
std::string MotionEvidence(const SyncEvent& e) {
  return Format(
      "motion energy peak %.3f vs background %.3f grey levels, frame-to-frame jitter %.3f",
      e.level,
      e.floor,
      e.noise);
}

// Clap: the end of a burst of motion. drop[k] = min(E[k-1], E[k]) - A(k), A(k) the mean
// of E[k+3], E[k+4] (after the two frames the contact can straddle).
std::vector<double> ClapDrops(const std::vector<double>& e, int64_t lo, int64_t hi) {
  std::vector<double> drop(e.size(), 0.0);
  for (int64_t k = lo + 1; k + 3 < hi; ++k) {
    const double after = k + 4 < hi ? 0.5 * (e[k + 3] + e[k + 4]) : e[k + 3];
    drop[k] = std::max(0.0, std::min(e[k - 1], e[k]) - after);
  }
  return drop;
}

// Flash: motion energy of the frames that got brighter, over the background.
std::vector<double> FlashRises(const MotionEnergy& m, int64_t lo, int64_t hi, double background) {
  std::vector<double> rise(m.energy.size(), 0.0);
  for (int64_t j = std::max<int64_t>(lo, 1); j < hi; ++j) {
    if (m.mean_grey[j] > m.mean_grey[j - 1]) rise[j] = std::max(0.0, m.energy[j] - background);
  }
  return rise;
}

}  // namespace

Status SyncOptions::Validate() const {
  if (!(video_fps >= 0 && video_fps <= 1000))
    return Status::Error("video_fps must be in [0, 1000]");
  if (!(search_s > 0 && search_s <= 3600)) return Status::Error("search_s must be in (0, 3600]");
  if (!(max_seconds > 0)) return Status::Error("max_seconds must be positive");
  return Status::Ok();
}

StatusOr<SyncEvent> FindAudioOnset(const std::string& path, const SyncOptions& options) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  std::vector<double> strength, level_db;
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
      double energy = 0, power = 0;
      for (int i = 1; i <= kFrame; ++i) {
        const double d = block[i] - block[i - 1];
        energy += d * d;
        power += double(block[i]) * block[i];
      }
      double before = 0;
      for (double h : history) before += h;
      before /= kHistory;
      const double eps = 1e-12 * kFrame;
      strength.push_back(k < kHistory ? 0.0 : 10.0 * std::log10((energy + eps) / (before + eps)));
      level_db.push_back(10.0 * std::log10(power / kFrame + 1e-12));
      history[k % kHistory] = energy;
    }
  }
  if (strength.empty()) return Status::Error(path + ": no audio samples");
  int64_t lo, hi, best, runner_at;
  const double frames_per_s = double(kRate) / kFrame;
  const int64_t n = static_cast<int64_t>(strength.size());
  Window(options.audio_near_s, options.search_s, frames_per_s, n, &lo, &hi);
  const double floor_db = Quantile(level_db, lo, hi, 0.5);
  // Peak level over the 50 ms from each frame; onsets that stay below the floor plus
  // kSyncMinAboveFloorDb are no candidates.
  std::vector<double> peak_db(level_db.size());
  std::vector<double> candidates(strength.size(), 0.0);
  for (int64_t k = 0; k < n; ++k) {
    peak_db[k] = *std::max_element(level_db.begin() + k, level_db.begin() + std::min(n, k + 25));
    candidates[k] = peak_db[k] >= floor_db + kSyncMinAboveFloorDb ? strength[k] : 0.0;
  }
  PeakAndRunnerUp(
      candidates, lo, hi, static_cast<int64_t>(kSyncSameEventS * frames_per_s), &best, &runner_at);
  if (best < 0) return Status::Error(path + ": the search window holds no audio");
  SyncEvent event;
  event.strength = candidates[best];
  event.floor = floor_db;
  event.level = peak_db[best];
  if (runner_at >= 0 && candidates[runner_at] > 0) {
    event.runner_up = candidates[runner_at];
    event.runner_up_time_s = static_cast<double>(runner_at) / frames_per_s;
  }
  // 1 - the runner-up's amplitude ratio to the winner (an onset below 0 dB is none).
  event.distinctness =
      1.0 - std::pow(10.0, -(event.strength - std::max(0.0, event.runner_up)) / 20.0);
  if (event.strength < kSyncMinOnsetDb) {
    return Status::Error(Format(
        "%s: no sound event: the strongest onset is %.1f dB over the preceding 50 ms (needs "
        ">= %.0f dB, peaking >= %.0f dB over the noise floor); peak level %.1f dBFS vs noise "
        "floor (median) %.1f dBFS",
        path.c_str(),
        event.strength,
        kSyncMinOnsetDb,
        kSyncMinAboveFloorDb,
        *std::max_element(level_db.begin() + lo, level_db.begin() + hi),
        event.floor));
  }
  if (event.distinctness < 1.0 - kSyncAmbiguousRatio) {
    return Status::Error(Format(
        "%s: ambiguous sound event: onsets at %.3f s (%.1f dB) and %.3f s (%.1f dB) are within "
        "%.1f dB of each other (noise floor %.1f dBFS); set audio_near_s to choose one",
        path.c_str(),
        static_cast<double>(best) / frames_per_s,
        event.strength,
        event.runner_up_time_s,
        event.runner_up,
        -20.0 * std::log10(kSyncAmbiguousRatio),
        event.floor));
  }
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
    double e = 0, sum = 0;
    for (size_t i = 0; i < gray.pixels.size(); ++i) sum += gray.pixels[i];
    if (!previous.empty()) {
      for (size_t i = 0; i < gray.pixels.size(); ++i) {
        e += std::abs(int(gray.pixels[i]) - int(previous.pixels[i]));
      }
      e /= static_cast<double>(gray.pixels.size());
    }
    out.energy.push_back(e);
    out.mean_grey.push_back(gray.pixels.empty() ? 0.0 : sum / double(gray.pixels.size()));
    std::swap(previous, gray);
  }
  if (out.energy.empty()) return Status::Error(path + ": no decodable video frames");
  return out;
}

StatusOr<SyncEvent> FindVideoEventInEnergy(const MotionEnergy& motion,
                                           double fps,
                                           const SyncOptions& options,
                                           const std::string& path) {
  const auto& e = motion.energy;
  const int64_t n = static_cast<int64_t>(e.size());
  if (n < 6) return Status::Error(path + ": too few video frames to find an event");
  int64_t lo, hi;
  Window(options.video_near_s, options.search_s, fps, n, &lo, &hi);
  lo = std::max<int64_t>(lo, 1);
  if (hi - lo < 6) return Status::Error(path + ": the search window holds too few video frames");
  SyncEvent event;
  event.floor = Quantile(e, lo, hi, 0.1);
  event.level = *std::max_element(e.begin() + lo, e.begin() + hi);
  event.noise = Jitter(e, lo, hi);
  const bool clap = options.video_event == VideoEvent::kClap;
  const std::vector<double> score =
      clap ? ClapDrops(e, lo, hi) : FlashRises(motion, lo, hi, Quantile(e, lo, hi, 0.25));
  int64_t best, runner_at;
  PeakAndRunnerUp(
      score, lo, hi, static_cast<int64_t>(std::ceil(kSyncSameEventS * fps)), &best, &runner_at);
  event.strength = score[best];
  if (runner_at >= 0 && score[runner_at] > 0) {
    event.runner_up = score[runner_at];
    event.runner_up_time_s = static_cast<double>(runner_at) / fps;
  }
  const char* what = clap ? "clap" : "flash";
  const char* change = clap ? "drop" : "rise";
  const double needed = std::max(kSyncMinMotionSnr * event.noise, kSyncMinMotionGrey);
  if (!(event.strength >= needed)) {
    return Status::Error(Format(
        "%s: no %s: the largest %s of motion energy is %.3f grey levels (needs >= %.3f: %.0fx "
        "the jitter and >= %.2f); %s",
        path.c_str(),
        what,
        change,
        event.strength,
        needed,
        kSyncMinMotionSnr,
        kSyncMinMotionGrey,
        MotionEvidence(event).c_str()));
  }
  event.distinctness = 1.0 - event.runner_up / event.strength;
  if (event.distinctness < 1.0 - kSyncAmbiguousRatio) {
    return Status::Error(Format(
        "%s: ambiguous %s: motion energy %ss by %.3f at %.3f s and by %.3f at %.3f s (within "
        "%.0f%%); %s; set video_near_s to choose one",
        path.c_str(),
        what,
        change,
        event.strength,
        static_cast<double>(best) / fps,
        event.runner_up,
        event.runner_up_time_s,
        100.0 * (1.0 - kSyncAmbiguousRatio),
        MotionEvidence(event).c_str()));
  }
  if (clap) {
    // best = K, the last frame moving through its whole exposure: the motion left
    // after it, in units of its own, is 1/2 + phi (sync.h).
    const double after = best + 4 < hi ? 0.5 * (e[best + 3] + e[best + 4]) : e[best + 3];
    const double full = e[best] - after;
    double left = 0;
    for (int64_t j = best + 1; j <= std::min(hi - 1, best + 3); ++j) {
      left += std::max(0.0, e[j] - after);
    }
    event.time_s = (static_cast<double>(best) + std::clamp(left / full, 0.0, 2.5)) / fps;
  } else {
    // The brightening's energy centroid over the frames around it (sync.h).
    const double base = Quantile(e, lo, hi, 0.25);
    double sum = 0, weighted = 0;
    for (int64_t j = std::max<int64_t>(1, best - 1); j <= std::min(n - 1, best + 1); ++j) {
      if (j != best && motion.mean_grey[j] <= motion.mean_grey[j - 1]) continue;
      const double w = std::max(0.0, e[j] - base);
      sum += w;
      weighted += w * static_cast<double>(j);
    }
    const double centroid = sum > 0 ? weighted / sum : static_cast<double>(best);
    event.time_s = (centroid - 0.5) / fps;
  }
  event.frame = std::lround(event.time_s * fps);
  return event;
}

namespace {

// The rate a video's events are timed at. video_fps is for image folders, which carry no
// rate; a video's own rate wins, and one that disagrees would shift the offset without a
// word (15 for a 30 fps video doubles every video time), so it is an error.
StatusOr<double> EventFps(const MotionEnergy& motion,
                          const SyncOptions& options,
                          const std::string& path) {
  if (options.video_fps > 0 && motion.fps > 0 &&
      !media::SameFrameRate(options.video_fps, motion.fps)) {
    return Status::Error(path + ": " + NumberText(motion.fps) +
                         " fps in the container, but video_fps = " + NumberText(options.video_fps) +
                         " (video_fps sets the rate of image folders only; leave it out)");
  }
  const double fps = options.video_fps > 0 ? options.video_fps : motion.fps;
  if (!(fps > 0)) return Status::Error(path + ": unknown frame rate; set video_fps");
  return fps;
}

}  // namespace

StatusOr<SyncEvent> FindVideoEvent(const std::string& path,
                                   const SyncOptions& options,
                                   double* fps_out) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  ARCO_ASSIGN_OR_RETURN(const MotionEnergy motion, ComputeMotionEnergy(path, options.max_seconds));
  ARCO_ASSIGN_OR_RETURN(const double fps, EventFps(motion, options, path));
  if (fps_out != nullptr) *fps_out = fps;
  return FindVideoEventInEnergy(motion, fps, options, path);
}

StatusOr<SyncResult> SyncAudioToVideos(const std::string& audio_path,
                                       const std::vector<SyncView>& views,
                                       const SyncOptions& options) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  if (views.empty()) return Status::Error("no video to sync with");
  SyncResult result;
  ARCO_ASSIGN_OR_RETURN(result.audio, FindAudioOnset(audio_path, options));
  std::vector<size_t> found;
  std::string errors;
  for (const SyncView& view : views) {
    SyncViewResult v;
    v.video = view.video;
    StatusOr<SyncEvent> event = Status::Error("not run");
    if (auto motion = ComputeMotionEnergy(view.video, options.max_seconds); !motion.ok()) {
      event = motion.status();
    } else {
      // A wrong frame rate is the options' error, not one view without an event.
      ARCO_ASSIGN_OR_RETURN(v.fps, EventFps(*motion, options, view.video));
      event = FindVideoEventInEnergy(*motion, v.fps, options, view.video);
    }
    if (event.ok()) {
      v.event = *event;
      const double frame = v.event.time_s * v.fps;
      v.global_frame = view.global_frame ? view.global_frame(frame) : frame;
      found.push_back(result.views.size());
    } else {
      v.error = event.status().message();
      errors += (errors.empty() ? "" : "; ") + v.error;
    }
    result.views.push_back(std::move(v));
  }
  if (found.empty()) {
    if (views.size() == 1) return Status::Error(errors);
    return Status::Error(Format("no clear video event in any of %zu videos: ", views.size()) +
                         errors);
  }
  const double fps = result.views[found[0]].fps;
  for (size_t i : found) {
    if (std::abs(result.views[i].fps - fps) > 1e-6 * fps) {
      return Status::Error(
          Format("%s and %s have different frame rates (%.3f and %.3f fps); "
                 "sync them separately",
                 result.views[found[0]].video.c_str(),
                 result.views[i].video.c_str(),
                 fps,
                 result.views[i].fps));
    }
  }
  // Consensus: the views within half a frame of the median event.
  std::vector<double> frames;
  for (size_t i : found) frames.push_back(result.views[i].global_frame);
  std::sort(frames.begin(), frames.end());
  const size_t m = frames.size();
  const double median = m % 2 ? frames[m / 2] : 0.5 * (frames[m / 2 - 1] + frames[m / 2]);
  double sum = 0, distinct = 0;
  size_t used = 0;
  for (size_t i : found) {
    SyncViewResult& v = result.views[i];
    v.used = std::abs(v.global_frame - median) <= 0.5;
    if (!v.used) continue;
    if (used == 0) result.video = v.event;
    ++used;
    sum += v.global_frame;
    distinct += v.event.distinctness;
  }
  if (2 * used < m || used == 0) {
    std::string list;
    for (size_t i : found) {
      list += Format("%s%s at frame %.2f",
                     list.empty() ? "" : ", ",
                     result.views[i].video.c_str(),
                     result.views[i].global_frame);
    }
    return Status::Error("the videos disagree on the event by more than half a frame: " + list);
  }
  result.video_fps = fps;
  result.event_global_frame = sum / static_cast<double>(used);
  result.offset_s = result.audio.time_s - result.event_global_frame / fps;
  const double agreement = static_cast<double>(used) / static_cast<double>(m);
  result.confidence =
      std::min(result.audio.distinctness, distinct / static_cast<double>(used)) * agreement;
  for (const SyncViewResult& v : result.views) {
    if (!v.error.empty()) {
      result.warnings.push_back("left out (no clear event): " + v.error);
    } else if (!v.used) {
      result.warnings.push_back(
          Format("left out: %s sees the event at frame %.2f, more than half a frame from the "
                 "other videos' %.2f",
                 v.video.c_str(),
                 v.global_frame,
                 median));
    }
  }
  if (result.confidence < kSyncLowConfidence) {
    result.warnings.push_back(
        Format("low confidence %.2f (< %.2f): runner-ups at %.1f dB (audio, winner %.1f dB) and "
               "%.3f (video, winner %.3f); check the offset or set audio_near_s / video_near_s",
               result.confidence,
               kSyncLowConfidence,
               result.audio.runner_up,
               result.audio.strength,
               result.video.runner_up,
               result.video.strength));
  }
  return result;
}

StatusOr<SyncResult> SyncAudioToVideo(const std::string& audio_path,
                                      const std::string& video_path,
                                      const SyncOptions& options) {
  return SyncAudioToVideos(audio_path, {SyncView{video_path, nullptr}}, options);
}

}  // namespace arco::audio
