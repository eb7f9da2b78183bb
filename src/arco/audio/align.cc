#include "arco/audio/align.h"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <numeric>

#include "arco/audio/audio_reader.h"
#include "arco/audio/resampler.h"
#include "arco/util/number_range.h"

namespace arco::audio {
namespace {

// FFTW's planner is not thread-safe.
std::mutex& AlignPlannerMutex() {
  static std::mutex mutex;
  return mutex;
}

std::string Fixed(double v, int digits) {
  char text[48];
  std::snprintf(text, sizeof text, "%.*f", digits, v);
  return text;
}

// GCC-PHAT: c[k] = whitened sum_n a[n + k] b[n] for k in [-(nb - 1), na - 1];
// values[k - min_lag]. Bins below min_hz (hum, rumble) are left out.
struct Correlation {
  std::vector<double> values;
  int64_t min_lag = 0;
  double at(int64_t k) const { return values[static_cast<size_t>(k - min_lag)]; }
  int64_t max_lag() const { return min_lag + static_cast<int64_t>(values.size()) - 1; }
};

constexpr double kPhatFloor = 0.1;  // of the mean cross-spectrum magnitude

Correlation GccPhat(const float* a, int64_t na, const float* b, int64_t nb, double rate_hz) {
  constexpr double kMinHz = 60.0;
  int64_t n = 1;
  while (n < na + nb) n *= 2;
  const int64_t bins = n / 2 + 1;
  double* time = fftw_alloc_real(static_cast<size_t>(n));
  fftw_complex* fa = fftw_alloc_complex(static_cast<size_t>(bins));
  fftw_complex* fb = fftw_alloc_complex(static_cast<size_t>(bins));
  fftw_plan forward_a, forward_b, inverse;
  {
    std::lock_guard<std::mutex> lock(AlignPlannerMutex());
    forward_a = fftw_plan_dft_r2c_1d(static_cast<int>(n), time, fa, FFTW_ESTIMATE);
    forward_b = fftw_plan_dft_r2c_1d(static_cast<int>(n), time, fb, FFTW_ESTIMATE);
    inverse = fftw_plan_dft_c2r_1d(static_cast<int>(n), fa, time, FFTW_ESTIMATE);
  }
  std::fill(time, time + n, 0.0);
  std::copy(a, a + na, time);
  fftw_execute(forward_a);
  std::fill(time, time + n, 0.0);
  std::copy(b, b + nb, time);
  fftw_execute(forward_b);
  double largest = 0;
  for (int64_t i = 0; i < bins; ++i) {
    const double re = fa[i][0] * fb[i][0] + fa[i][1] * fb[i][1];
    const double im = fa[i][1] * fb[i][0] - fa[i][0] * fb[i][1];
    fa[i][0] = re;
    fa[i][1] = im;
    largest = std::max(largest, std::hypot(re, im));
  }
  const int64_t first_bin = static_cast<int64_t>(std::ceil(kMinHz * double(n) / rate_hz));
  double mean = 0;
  for (int64_t i = first_bin; i < bins; ++i) mean += std::hypot(fa[i][0], fa[i][1]);
  mean /= double(std::max<int64_t>(1, bins - first_bin));
  // Regularised PHAT: 1 / (|X| + floor). Bins far below the mean (between a periodic
  // sound's harmonics, numerical noise) would otherwise vote as loudly as the sound
  // itself, and their votes are about the recordings' edges, not their content.
  const double floor = kPhatFloor * mean;
  for (int64_t i = 0; i < bins; ++i) {
    const double mag = std::hypot(fa[i][0], fa[i][1]);
    const double w = (i < first_bin || !(mag > 1e-12 * largest)) ? 0.0 : 1.0 / (mag + floor);
    fa[i][0] *= w;
    fa[i][1] *= w;
  }
  fftw_execute(inverse);
  Correlation c;
  c.min_lag = -(nb - 1);
  c.values.resize(static_cast<size_t>(na + nb - 1));
  for (int64_t k = c.min_lag; k <= na - 1; ++k) {
    c.values[static_cast<size_t>(k - c.min_lag)] = time[(k + n) % n] / double(n);
  }
  {
    std::lock_guard<std::mutex> lock(AlignPlannerMutex());
    fftw_destroy_plan(forward_a);
    fftw_destroy_plan(forward_b);
    fftw_destroy_plan(inverse);
  }
  fftw_free(time);
  fftw_free(fa);
  fftw_free(fb);
  return c;
}

struct Peak {
  int64_t lag = 0;
  double value = -1e300;
  double runner_up = -1e300;
  int64_t runner_up_lag = 0;
  double refined = 0;  // lag with the parabola's sub-sample correction
};

// The largest value over [lo, hi], and the largest more than `exclusion` samples away.
Peak FindPeak(const Correlation& c, int64_t lo, int64_t hi, int64_t exclusion) {
  Peak p;
  for (int64_t k = lo; k <= hi; ++k) {
    if (c.at(k) > p.value) {
      p.value = c.at(k);
      p.lag = k;
    }
  }
  for (int64_t k = lo; k <= hi; ++k) {
    if (std::llabs(k - p.lag) > exclusion && c.at(k) > p.runner_up) {
      p.runner_up = c.at(k);
      p.runner_up_lag = k;
    }
  }
  p.refined = double(p.lag);
  if (p.lag > c.min_lag && p.lag < c.max_lag()) {
    const double ym = c.at(p.lag - 1), y0 = c.at(p.lag), yp = c.at(p.lag + 1);
    const double den = ym - 2 * y0 + yp;
    if (den < 0) p.refined += std::clamp(0.5 * (ym - yp) / den, -0.5, 0.5);
  }
  return p;
}

double RmsDbfs(const float* x, int64_t n) {
  double sum = 0;
  for (int64_t i = 0; i < n; ++i) sum += double(x[i]) * x[i];
  return n > 0 ? 10 * std::log10(sum / double(n) + 1e-30) : -300;
}

std::vector<float> Resample(const std::vector<float>& in, int from_hz, int to_hz) {
  Resampler r(from_hz, to_hz);
  std::vector<float> out;
  std::vector<float> block(8192);
  r.Push(in.data(), static_cast<int64_t>(in.size()));
  r.Finish();
  while (!r.done()) {
    const int64_t got = r.Pull(block.data(), static_cast<int64_t>(block.size()));
    if (got == 0) break;
    out.insert(out.end(), block.begin(), block.begin() + got);
  }
  return out;
}

}  // namespace

Status AlignOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(
      CheckInRange("fine_rate_hz", double(fine_rate_hz), Closed(kAlignCoarseRateHz, 96000)));
  ARCO_RETURN_IF_ERROR(CheckInRange("max_seconds", max_seconds, Closed(1, 86400)));
  ARCO_RETURN_IF_ERROR(CheckInRange("max_lag_s", max_lag_s, Closed(0, 86400)));
  ARCO_RETURN_IF_ERROR(CheckInRange("window_s", window_s, Closed(0.5, 60)));
  ARCO_RETURN_IF_ERROR(CheckInRange("max_windows", double(max_windows), Closed(1, 1000)));
  ARCO_RETURN_IF_ERROR(CheckInRange("max_drift_ppm", max_drift_ppm, Closed(0, 10000)));
  ARCO_RETURN_IF_ERROR(CheckInRange("min_drift_span_s", min_drift_span_s, Closed(1, 86400)));
  ARCO_RETURN_IF_ERROR(CheckInRange("ambiguous_ratio", ambiguous_ratio, Closed(0.05, 0.99)));
  ARCO_RETURN_IF_ERROR(CheckInRange("outlier_s", outlier_s, Closed(1e-5, 1)));
  return Status::Ok();
}

double TrackLevelDbfs(const AudioTrack& track) {
  return RmsDbfs(track.samples.data(), static_cast<int64_t>(track.samples.size()));
}

StatusOr<AudioTrack> LoadAudioTrack(const std::string& path, int rate_hz, double max_seconds) {
  ARCO_ASSIGN_OR_RETURN(std::unique_ptr<AudioReader> reader, OpenAudio(path));
  const int source_rate = reader->info().sample_rate_hz;
  const int64_t limit = static_cast<int64_t>(std::ceil(max_seconds * source_rate));
  std::vector<float> samples;
  std::vector<float> block(8192);
  while (static_cast<int64_t>(samples.size()) < limit) {
    ARCO_ASSIGN_OR_RETURN(const int64_t got,
                          reader->ReadMono(block.data(), static_cast<int64_t>(block.size())));
    if (got == 0) break;
    samples.insert(samples.end(), block.begin(), block.begin() + got);
  }
  if (static_cast<int64_t>(samples.size()) > limit) samples.resize(static_cast<size_t>(limit));
  if (samples.empty()) return Status::Error(path + ": the audio track holds no samples");
  AudioTrack track;
  track.source = path;
  track.rate_hz = rate_hz;
  track.samples =
      source_rate == rate_hz ? std::move(samples) : Resample(samples, source_rate, rate_hz);
  return track;
}

StatusOr<AlignResult> AlignTracks(const AudioTrack& ref,
                                  const AudioTrack& other,
                                  const AlignOptions& o) {
  ARCO_RETURN_IF_ERROR(o.Validate());
  if (ref.rate_hz != o.fine_rate_hz || other.rate_hz != o.fine_rate_hz) {
    throw std::invalid_argument("AlignTracks: tracks must be at options.fine_rate_hz");
  }
  for (const AudioTrack* t : {&ref, &other}) {
    const double level = RmsDbfs(t->samples.data(), static_cast<int64_t>(t->samples.size()));
    if (level < kAlignSilentDbfs) {
      return Status::Error(t->source + ": the audio track is silent (" + Fixed(level, 0) +
                           " dBFS RMS, below " + Fixed(kAlignSilentDbfs, 0) +
                           "): nothing to sync by");
    }
  }
  const std::string pair = other.source + " against " + ref.source;
  const double fs = o.fine_rate_hz;
  const double len_r = ref.duration_s(), len_o = other.duration_s();

  // 1. Global lag at the coarse rate.
  const double cs = kAlignCoarseRateHz;
  std::vector<float> cr = Resample(ref.samples, o.fine_rate_hz, kAlignCoarseRateHz);
  std::vector<float> co = Resample(other.samples, o.fine_rate_hz, kAlignCoarseRateHz);
  // Faded in and out (raised cosine over a tenth of each, at most 1 s): the whitened
  // spectrum of a periodic sound is mostly its edges, and sharp edges would make the
  // lag that lines them up win over the other beats.
  for (std::vector<float>* x : {&cr, &co}) {
    const size_t fade = std::min<size_t>(static_cast<size_t>(cs), x->size() / 10);
    for (size_t i = 0; i < fade; ++i) {
      const float w = static_cast<float>(0.5 - 0.5 * std::cos(M_PI * (i + 0.5) / fade));
      (*x)[i] *= w;
      (*x)[x->size() - 1 - i] *= w;
    }
  }
  const Correlation global = GccPhat(
      cr.data(), static_cast<int64_t>(cr.size()), co.data(), static_cast<int64_t>(co.size()), cs);
  // Lags leaving less overlap than this are not searched (a few samples always correlate).
  const double min_overlap_s = std::min(1.0, 0.5 * std::min(len_r, len_o));
  double lo_s = -(len_o - min_overlap_s), hi_s = len_r - min_overlap_s;
  if (o.max_lag_s > 0) {
    lo_s = std::max(lo_s, -o.max_lag_s);
    hi_s = std::min(hi_s, o.max_lag_s);
  }
  const int64_t lo = std::max(global.min_lag, static_cast<int64_t>(std::ceil(lo_s * cs)));
  const int64_t hi = std::min(global.max_lag(), static_cast<int64_t>(std::floor(hi_s * cs)));
  if (lo > hi) return Status::Error(pair + ": the recordings are too short to align");
  const double drift_smear_s = o.max_drift_ppm * 1e-6 * std::max(len_r, len_o);
  const double exclusion_s = 0.02 + drift_smear_s;
  const Peak gp = FindPeak(global, lo, hi, static_cast<int64_t>(std::ceil(exclusion_s * cs)));
  AlignResult result;
  const double ratio = gp.value > 0 ? std::max(0.0, gp.runner_up) / gp.value : 1.0;
  result.confidence = std::clamp(1.0 - ratio, 0.0, 1.0);
  result.runner_up_lag_s = double(gp.runner_up_lag) / cs;
  const double lag0 = gp.refined / cs;
  if (!(gp.value > 0) || ratio > o.ambiguous_ratio) {
    return Status::Error(pair + ": ambiguous alignment: the sound matches at " + Fixed(lag0, 4) +
                         " s and almost as well (" + Fixed(100 * ratio, 0) + " %) at " +
                         Fixed(result.runner_up_lag_s, 4) +
                         " s (a periodic sound, or not the same sound?)");
  }

  // 2. Local lags in windows over the overlap (other's clock).
  const double margin_s = 2.0 / cs + 0.005 + drift_smear_s;
  const double overlap_lo = std::max(0.0, -lag0), overlap_hi = std::min(len_o, len_r - lag0);
  const double window_s = std::min(o.window_s, overlap_hi - overlap_lo - 2 * margin_s - 0.01);
  if (window_s < 0.25) {
    return Status::Error(pair + ": the recordings overlap by " + Fixed(overlap_hi - overlap_lo, 2) +
                         " s only; too short to align");
  }
  const double c_lo = overlap_lo + margin_s + 0.5 * window_s + 0.002;
  const double c_hi = overlap_hi - margin_s - 0.5 * window_s - 0.002;
  const int count =
      std::clamp(static_cast<int>(std::floor((c_hi - c_lo) / window_s)) + 1, 1, o.max_windows);
  const int64_t wn = static_cast<int64_t>(std::llround(window_s * fs));
  const int64_t mn = static_cast<int64_t>(std::ceil(margin_s * fs));
  std::vector<double> xs, ys;
  result.windows = count;
  for (int i = 0; i < count; ++i) {
    const double c = count == 1 ? 0.5 * (c_lo + c_hi) : c_lo + (c_hi - c_lo) * i / (count - 1);
    const int64_t so = static_cast<int64_t>(std::llround((c - 0.5 * window_s) * fs));
    const int64_t sr = static_cast<int64_t>(std::llround((c + lag0 - 0.5 * window_s) * fs)) - mn;
    const int64_t nr = wn + 2 * mn;
    if (so < 0 || so + wn > static_cast<int64_t>(other.samples.size()) || sr < 0 ||
        sr + nr > static_cast<int64_t>(ref.samples.size())) {
      continue;
    }
    const float* a = ref.samples.data() + sr;
    const float* b = other.samples.data() + so;
    if (RmsDbfs(a, nr) < kAlignSilentDbfs || RmsDbfs(b, wn) < kAlignSilentDbfs) continue;
    const Correlation local = GccPhat(a, nr, b, wn, fs);
    const Peak p = FindPeak(local, 0, 2 * mn, static_cast<int64_t>(std::ceil(0.002 * fs)));
    if (!(p.value > 0) || (p.runner_up > 0 && p.runner_up / p.value > o.ambiguous_ratio)) continue;
    if (p.lag == 0 || p.lag == 2 * mn) continue;  // at the edge: not the peak
    xs.push_back(double(so) / fs + 0.5 * window_s);
    ys.push_back((double(sr - so) + p.refined) / fs);
  }
  if (xs.empty()) {
    return Status::Error(pair +
                         ": no stretch of the recordings correlates clearly (silent or "
                         "different sounds?)");
  }

  // 3. The line through the local lags.
  std::vector<bool> use(xs.size(), true);
  double offset = 0, slope = 0;
  const auto fit = [&]() {
    int n = 0;
    double mx = 0, my = 0;
    for (size_t i = 0; i < xs.size(); ++i) {
      if (!use[i]) continue;
      ++n;
      mx += xs[i];
      my += ys[i];
    }
    mx /= n;
    my /= n;
    double sxx = 0, sxy = 0, lo_x = 1e300, hi_x = -1e300;
    for (size_t i = 0; i < xs.size(); ++i) {
      if (!use[i]) continue;
      sxx += (xs[i] - mx) * (xs[i] - mx);
      sxy += (xs[i] - mx) * (ys[i] - my);
      lo_x = std::min(lo_x, xs[i]);
      hi_x = std::max(hi_x, xs[i]);
    }
    result.span_s = hi_x - lo_x;
    slope = (n >= 3 && result.span_s >= o.min_drift_span_s && sxx > 0) ? sxy / sxx : 0.0;
    offset = my - slope * mx;
    result.windows_used = n;
  };
  fit();
  // One pass against windows off the line, around the median residual (robust to a
  // wrong window pulling the first fit).
  std::vector<double> residuals;
  for (size_t i = 0; i < xs.size(); ++i) residuals.push_back(ys[i] - (offset + slope * xs[i]));
  std::vector<double> sorted = residuals;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double median = sorted[sorted.size() / 2];
  bool dropped = false;
  for (size_t i = 0; i < xs.size(); ++i) {
    if (std::abs(residuals[i] - median) > o.outlier_s) {
      use[i] = false;
      dropped = true;
    }
  }
  if (dropped) {
    if (std::none_of(use.begin(), use.end(), [](bool u) { return u; })) {
      return Status::Error(pair + ": the windows' lags disagree by more than " +
                           Fixed(1000 * o.outlier_s, 1) + " ms; no consistent alignment");
    }
    fit();
  }
  double sum2 = 0;
  for (size_t i = 0; i < xs.size(); ++i) {
    if (use[i]) sum2 += std::pow(ys[i] - (offset + slope * xs[i]), 2);
  }
  result.residual_rms_s = std::sqrt(sum2 / result.windows_used);
  result.offset_s = offset;
  result.drift_ppm = slope * 1e6;
  if (std::abs(result.drift_ppm) > o.max_drift_ppm) {
    return Status::Error(pair + ": clock drift of " + Fixed(result.drift_ppm, 0) + " ppm, beyond " +
                         Fixed(o.max_drift_ppm, 0) + " ppm");
  }
  return result;
}

}  // namespace arco::audio
