#include "arco/audio/double_stops.h"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <stdexcept>
#include <utility>
#include <vector>

#include "arco/audio/sample_stream.h"
#include "arco/registry/instruments.h"

namespace arco::audio {
namespace {

// Klapuri 2006, eq. 3: the weight of partial m of f0 f (alpha, beta in Hz).
constexpr double kAlphaHz = 52.0, kBetaHz = 320.0;
// A partial is looked for within +-25 cents of m f (the grid is finer; bowed strings are
// harmonic to a few cents).
constexpr double kPartialCents = 25.0;
// Notes closer than this are one note (the residual of a vibrato's smeared peak).
constexpr double kMinIntervalSemitones = 0.8;

// A note's octave below is the note when its odd partials (none of them the heard note's)
// carry at least this share of its even partials' weighted amplitude (check (4)): 0.2-0.6
// for fluidsynth's violin B3 and double bass G#1 (whose fundamentals are 5-30% of their
// 2nd partials), leakage only (< 0.05) for a note with nothing an octave below.
constexpr double kLostFundamentalOddRatio = 0.15;

// A fifth is one note's 2nd and 3rd partials when that note's partials prime to 6 carry at
// least this share of its 2nd and 3rd's weighted amplitude (check (5)): 0.16-0.25 for
// fluidsynth's cello C2 and D2 (fundamentals 5-9% of the strongest partial).
constexpr double kPartialFifthRatio = 0.1;

// Auto window: periods of the lowest f0, so that the partials of a third on the lowest
// strings (4 Hz apart at the double bass's 40 Hz) are at least a Hann main lobe apart.
constexpr double kAutoWindowPeriods = 8.0;

// PairOnStrings: the candidates of the string taken first that are tried (the loudest
// few: a pair's partials and ghosts rank among them, its notes too).
constexpr int kPairFirstCandidates = 3;
// PairOnStrings: the share of the free analysis's bar a fundamental must reach.
constexpr double kPairFundamentalShare = 0.5;
// PairOnStrings: the highest stop of either note (semitones above its open string), just
// below the octave. Without a bound every pair of strings holds every high pair, a note
// and its 2nd partial among them; at the octave itself an open string's 2nd and 3rd
// partials are a pair on its string and the next (the cello's open C2 + C3 heard as C3 +
// G3 at 12 semitones on the C and G strings). A double stop higher up the bowed strings
// is taken for a pair below the bound: a limit of this reading (docs/audio.md).
constexpr double kPairMaxStopSemitones = 11.5;

double Weight(double f_hz, int m) { return (f_hz + kAlphaHz) / (m * f_hz + kBetaHz); }

// Partial m's amplitude that is its note's after the spectral-smoothness rule (Klapuri
// 2003): min(A_m, sqrt(A_{m-1} A_{m+1})), the last partial against its one neighbour;
// amplitude[1..count].
double OwnAmplitude(const double* amplitude, int m, int count) {
  if (m == 1) return amplitude[1];
  const double next = m < count ? amplitude[m + 1] : amplitude[m - 1];
  return std::min(amplitude[m], std::sqrt(amplitude[m - 1] * next));
}

}  // namespace

Status DoubleStopOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(CheckInRange("fps", fps, kTrackerFpsRange));
  ARCO_RETURN_IF_ERROR(CheckInRange("start_s", start_s, kTrackerStartRangeS));
  if (max_frames < -1) return Status::Error("max_frames must be >= -1");
  ARCO_RETURN_IF_ERROR(CheckInRange("a4_hz", a4_hz, kA4RangeHz));
  ARCO_RETURN_IF_ERROR(CheckInRange("window_s", window_s, kDoubleStopWindowRangeS));
  ARCO_RETURN_IF_ERROR(CheckInRange("harmonics", harmonics, kDoubleStopHarmonicsRange));
  ARCO_RETURN_IF_ERROR(CheckInRange("grid_cents", grid_cents, kDoubleStopGridRangeCents));
  ARCO_RETURN_IF_ERROR(CheckInRange("second_min_ratio", second_min_ratio, kDoubleStopRatioRange));
  ARCO_RETURN_IF_ERROR(
      CheckInRange("min_fundamental_ratio", min_fundamental_ratio, kDoubleStopRatioRange));
  ARCO_RETURN_IF_ERROR(
      CheckInRange("max_span_semitones", max_span_semitones, kDoubleStopSpanRangeSemitones));
  ARCO_RETURN_IF_ERROR(CheckInRange("silence_db", silence_db, kDoubleStopSilenceRangeDb));
  ARCO_RETURN_IF_ERROR(CheckInRange("consistency_s", consistency_s, kDoubleStopConsistencyRangeS));
  const double top_hz = range.analysis_rate_hz / 4.0;
  if (!(range.min_f0_hz >= 20 && range.min_f0_hz < range.max_f0_hz && range.max_f0_hz <= top_hz)) {
    return Status::Error("double stops: min_f0_hz = " + NumberText(range.min_f0_hz) +
                         " and max_f0_hz = " + NumberText(range.max_f0_hz) +
                         " Hz must satisfy 20 <= min_f0_hz < max_f0_hz <= " + NumberText(top_hz));
  }
  return Status::Ok();
}

double DoubleStopWindowS(const DoubleStopOptions& options) {
  return options.window_s > 0 ? options.window_s
                              : std::max(0.1, kAutoWindowPeriods / options.range.min_f0_hz);
}

bool PlayableDoubleStop(const std::array<double, 4>& open_midi_low_to_high,
                        double low_midi,
                        double high_midi,
                        double max_span_semitones) {
  if (!(high_midi > low_midi)) return false;
  for (int s = 0; s + 1 < 4; ++s) {
    const double low_stop = low_midi - open_midi_low_to_high[s];
    const double high_stop = high_midi - open_midi_low_to_high[s + 1];
    if (low_stop < -0.5 || high_stop < -0.5) continue;
    if (std::abs(high_stop - low_stop) <= max_span_semitones) return true;
  }
  return false;
}

DoubleStopAnalyzer::DoubleStopAnalyzer(const DoubleStopOptions& options) : options_(options) {
  const Status valid = options.Validate();
  if (!valid.ok()) throw std::invalid_argument(valid.message());
  const double rate = options.range.analysis_rate_hz;
  window_ = static_cast<int>(std::lround(DoubleStopWindowS(options) * rate));
  fft_size_ = 1;
  while (fft_size_ < 2 * window_) fft_size_ *= 2;
  bin_hz_ = rate / fft_size_;
  // Hann main lobe: +-2 bins of the unpadded transform.
  lobe_bins_ = static_cast<int>(std::ceil(2.0 * fft_size_ / window_));
  floor_ = std::pow(10.0, options.silence_db / 20.0);
  hann_.resize(window_);
  for (int j = 0; j < window_; ++j) {
    const double s = std::sin(M_PI * (j + 0.5) / window_);
    hann_[j] = s * s;
  }
  const StatusOr<InstrumentKind> kind = ParseInstrumentKind(options.range.name);
  has_strings_ = kind.ok();
  if (has_strings_) {
    const auto& open = GetInstrumentInfo(*kind).open_midi_low_to_high;
    for (int s = 0; s < 4; ++s) open_midi_[s] = open[s];
  }
  const int harmonics = options.harmonics;
  const double spread = std::exp2(kPartialCents / 1200.0);
  for (double f = options.range.min_f0_hz; f <= options.range.max_f0_hz;
       f *= std::exp2(options.grid_cents / 1200.0)) {
    candidates_hz_.push_back(f);
    candidates_midi_.push_back(69.0 + 12.0 * std::log2(f / options.a4_hz));
    for (int m = 1; m <= harmonics; ++m) {
      const double hi_hz = m * f * spread;
      if (hi_hz >= 0.45 * rate) {
        bands_.push_back({-1, -1});
        continue;
      }
      const int lo = std::max(1, static_cast<int>(std::floor(m * f / spread / bin_hz_)));
      const int hi = std::max(lo, static_cast<int>(std::ceil(hi_hz / bin_hz_)));
      bands_.push_back({lo, hi});
    }
  }
  time_ = fftw_alloc_real(fft_size_);
  auto* spectrum = fftw_alloc_complex(fft_size_ / 2 + 1);
  spectrum_ = spectrum;
  plan_ = fftw_plan_dft_r2c_1d(fft_size_, time_, spectrum, FFTW_ESTIMATE);
  magnitude_.assign(fft_size_ / 2 + 1, 0.0);
  residual_ = magnitude_;
  for (auto* v : {&partial_hz_, &partial_amplitude_}) v->reserve(harmonics + 2);
  partial_index_.reserve(harmonics + 2);
}

DoubleStopAnalyzer::~DoubleStopAnalyzer() {
  fftw_destroy_plan(static_cast<fftw_plan>(plan_));
  fftw_free(time_);
  fftw_free(spectrum_);
}

double DoubleStopAnalyzer::BandMax(int candidate,
                                   int m,
                                   const std::vector<double>& spectrum,
                                   int* at) const {
  const auto& band = bands_[static_cast<size_t>(candidate) * options_.harmonics + m - 1];
  if (band[0] < 0) return -1.0;
  int best = band[0];
  for (int k = band[0] + 1; k <= band[1]; ++k) {
    if (spectrum[k] > spectrum[best]) best = k;
  }
  if (at != nullptr) *at = best;
  return spectrum[best];
}

double BandPeak(const std::vector<double>& spectrum, int lo, int hi) {
  if (lo < 0 || hi < lo || hi >= static_cast<int>(spectrum.size())) return -1.0;
  int k = lo;
  for (int j = lo + 1; j <= hi; ++j) {
    if (spectrum[j] > spectrum[k]) k = j;
  }
  const double a = spectrum[k];
  const bool below = k > 0 && spectrum[k - 1] > a;
  const bool above = k + 1 < static_cast<int>(spectrum.size()) && spectrum[k + 1] > a;
  return below || above ? 0.0 : a;
}

double DoubleStopAnalyzer::Fundamental(int candidate, const std::vector<double>& spectrum) const {
  const auto& band = bands_[static_cast<size_t>(candidate) * options_.harmonics];
  return band[0] < 0 ? -1.0 : BandPeak(spectrum, band[0], band[1]);
}

double DoubleStopAnalyzer::Salience(int candidate, const std::vector<double>& spectrum) const {
  double s = 0;
  for (int m = 1; m <= options_.harmonics; ++m) {
    const double a = BandMax(candidate, m, spectrum, nullptr);
    if (a < 0) break;
    s += Weight(candidates_hz_[candidate], m) * a;
  }
  return s;
}

// The best candidate of `spectrum` whose fundamental is present; with first >= 0, only
// candidates that form a playable double stop with it.
DoubleStopAnalyzer::Best DoubleStopAnalyzer::Search(const std::vector<double>& spectrum,
                                                    int first) const {
  const double peak = *std::max_element(magnitude_.begin(), magnitude_.end());
  const double min_fundamental = options_.min_fundamental_ratio * peak;
  Best best;
  for (int c = 0; c < static_cast<int>(candidates_hz_.size()); ++c) {
    if (first >= 0) {
      const double a = candidates_midi_[first], b = candidates_midi_[c];
      if (std::abs(a - b) < kMinIntervalSemitones) continue;
      if (has_strings_ &&
          !PlayableDoubleStop(
              open_midi_, std::min(a, b), std::max(a, b), options_.max_span_semitones)) {
        continue;
      }
    }
    // (2): the fundamental is present; an octave above the first note is exempt, its
    // fundamental is the first note's 2nd partial, which may have interfered away.
    const bool octave = first >= 0 && std::abs(candidates_midi_[c] - candidates_midi_[first] -
                                               12.0) < kPartialCents / 100.0;
    if (!octave && Fundamental(c, spectrum) < min_fundamental) continue;
    const double s = Salience(c, spectrum);
    if (s > best.salience) best = {c, s};
  }
  return best;
}

// f0 of candidate c from the frequencies of its partials in `spectrum` (the salience is flat
// to within the +-25 cent partial band, so the grid maximum alone is biased): each partial's
// peak refined by the vertex of a parabola through the log magnitudes of its bin and the
// two neighbours, then f0 = sum(A_m^2 m f_m) / sum(A_m^2 m^2), the least-squares fit of
// f_m = m f0 weighted by A_m^2 (as HarmonicPeakFit, harmonic_fit.h); partials below 10% of
// the strongest are left out.
double DoubleStopAnalyzer::Refine(int c, const std::vector<double>& spectrum) {
  std::vector<double>& freq = partial_hz_;
  std::vector<double>& amp = partial_amplitude_;
  std::vector<int>& harmonic = partial_index_;
  freq.clear(), amp.clear(), harmonic.clear();
  for (int m = 1; m <= options_.harmonics; ++m) {
    int k = -1;
    if (BandMax(c, m, spectrum, &k) < 0) break;
    if (k <= 0 || k >= fft_size_ / 2) continue;
    const double a = std::log(spectrum[k - 1] + 1e-12), b = std::log(spectrum[k] + 1e-12),
                 d = std::log(spectrum[k + 1] + 1e-12);
    const double den = a - 2.0 * b + d;
    if (!(den < 0) || a > b || d > b) continue;  // no peak at k
    const double delta = 0.5 * (a - d) / den;
    freq.push_back((k + delta) * bin_hz_);
    amp.push_back(spectrum[k]);
    harmonic.push_back(m);
  }
  if (freq.empty()) return candidates_hz_[c];
  const double strongest = *std::max_element(amp.begin(), amp.end());
  double num = 0, den = 0;
  for (size_t i = 0; i < freq.size(); ++i) {
    if (amp[i] < 0.1 * strongest) continue;
    const double w = amp[i] * amp[i], m = harmonic[i];
    num += w * m * freq[i];
    den += w * m * m;
  }
  return den > 0 ? num / den : candidates_hz_[c];
}

// Cancels the partials of candidate c from residual_ after the spectral-smoothness rule
// (Klapuri 2003): partial m keeps min(A_m, sqrt(A_{m-1} A_{m+1})) as this note's (the
// geometric mean of its neighbours: the arithmetic one, above a k^-1 envelope, took all of
// an octave's shared partials), and
// its main lobe is scaled by the share left to other notes, 1 - that / A_m. Returns the
// salience of what it cancelled (eq. 3 on the note's own partials).
double DoubleStopAnalyzer::Cancel(int c) {
  const int harmonics = options_.harmonics;
  std::vector<double>& amplitude = partial_amplitude_;
  std::vector<int>& at = partial_index_;
  amplitude.assign(harmonics + 2, 0.0);
  at.assign(harmonics + 2, -1);
  int count = 0;
  for (int m = 1; m <= harmonics; ++m) {
    const double a = BandMax(c, m, residual_, &at[m]);
    if (a < 0) break;
    amplitude[m] = a;
    count = m;
  }
  double own_salience = 0;
  for (int m = 1; m <= count; ++m) {
    const double own = OwnAmplitude(amplitude.data(), m, count);
    own_salience += Weight(candidates_hz_[c], m) * own;
    const double keep = amplitude[m] > 0 ? 1.0 - own / amplitude[m] : 0.0;
    const int lo = std::max(0, at[m] - lobe_bins_),
              hi = std::min(fft_size_ / 2, at[m] + lobe_bins_);
    for (int k = lo; k <= hi; ++k) residual_[k] *= keep;
  }
  return own_salience;
}

// The candidate an octave below `note` when it is the pair's true note (checks (1) and (2)
// with `partner`, and its odd partials, on the spectrum without the partner, carry at least
// kLostFundamentalOddRatio of its even ones' salience: a single note's octave below has
// nothing at its odd partials but leakage); else -1. On success residual_ is the spectrum
// without the partner.
int DoubleStopAnalyzer::LostFundamental(int note, int partner) {
  const int below = note - static_cast<int>(std::lround(1200.0 / options_.grid_cents));
  if (below < 0) return -1;
  const double a = candidates_midi_[partner], b = candidates_midi_[below];
  if (std::abs(a - b) < kMinIntervalSemitones) return -1;
  if (has_strings_ &&
      !PlayableDoubleStop(
          open_midi_, std::min(a, b), std::max(a, b), options_.max_span_semitones)) {
    return -1;
  }
  residual_ = magnitude_;
  Cancel(partner);
  const double peak = *std::max_element(magnitude_.begin(), magnitude_.end());
  // Half the usual bar: the low strings' fundamentals (a double bass's E1 at 41 Hz) are
  // 2-5% of the strongest partial; the odd partials below are the stronger evidence.
  if (Fundamental(below, residual_) < 0.5 * options_.min_fundamental_ratio * peak) {
    return -1;
  }
  double odd = 0, even = 0;
  for (int m = 1; m <= options_.harmonics; ++m) {
    const double amplitude = BandMax(below, m, residual_, nullptr);
    if (amplitude < 0) break;
    (m % 2 == 1 ? odd : even) += Weight(candidates_hz_[below], m) * amplitude;
  }
  return even > 0 && odd >= kLostFundamentalOddRatio * even ? below : -1;
}

// The candidate an octave below `low` when `low` and `high` are a fifth (3:2) that is its
// 2nd and 3rd partials: its fundamental is present (2.5% of the strongest peak) and its
// partials that neither heard note has (m = 1, 5, 7, 11: prime to 6) carry at least
// kPartialFifthRatio of the weighted amplitude of its 2nd and 3rd; else -1. A true fifth
// (C3 + G3) has nothing at 65, 327 or 458 Hz but leakage.
int DoubleStopAnalyzer::PartialFifth(int low, int high) const {
  const double fifth = candidates_midi_[high] - candidates_midi_[low];
  if (std::abs(fifth - 12.0 * std::log2(1.5)) > kPartialCents / 100.0) return -1;
  const int below = low - static_cast<int>(std::lround(1200.0 / options_.grid_cents));
  if (below < 0) return -1;
  const double peak = *std::max_element(magnitude_.begin(), magnitude_.end());
  if (Fundamental(below, magnitude_) < 0.5 * options_.min_fundamental_ratio * peak) {
    return -1;
  }
  double unique = 0, heard = 0;
  for (int m = 1; m <= options_.harmonics; ++m) {
    const double amplitude = BandMax(below, m, magnitude_, nullptr);
    if (amplitude < 0) break;
    const double weighted = Weight(candidates_hz_[below], m) * amplitude;
    if (m == 2 || m == 3) heard += weighted;
    if (m % 2 != 0 && m % 3 != 0) unique += weighted;
  }
  return heard > 0 && unique >= kPartialFifthRatio * heard ? below : -1;
}

int DoubleStopAnalyzer::Analyze(const float* x,
                                std::array<PolyNote, 2>* notes,
                                std::array<std::array<PolyNote, 2>, kStringPairs>* on_strings) {
  *notes = {};
  if (on_strings != nullptr) *on_strings = {};
  double mean = 0;
  for (int j = 0; j < window_; ++j) mean += x[j];
  mean /= window_;
  double energy = 0;
  for (int j = 0; j < window_; ++j) {
    const double v = x[j] - mean;
    energy += v * v;
    time_[j] = v * hann_[j];
  }
  if (std::sqrt(energy / window_) < floor_) return 0;
  std::fill(time_ + window_, time_ + fft_size_, 0.0);
  fftw_execute(static_cast<fftw_plan>(plan_));
  const auto* spectrum = static_cast<const fftw_complex*>(spectrum_);
  for (int k = 0; k <= fft_size_ / 2; ++k)
    magnitude_[k] = std::hypot(spectrum[k][0], spectrum[k][1]);
  const int count = FreePair(notes);
  if (on_strings != nullptr && has_strings_) {
    // on_strings[s - 1] holds strings s + 1 and s (1 = highest): the pair whose lower
    // string is open_midi_[q] (low to high) is s = kStringPairs - q.
    // The free pair where it can be played on those strings (its checks are the finer:
    // the search on every frame lost the cello's and the double bass's double stops,
    // 0.942 -> 0.790 and 0.870 -> 0.583 of their frames' strings); the search on the
    // strings where it cannot.
    for (int q = 0; q < kStringPairs; ++q) {
      (*on_strings)[kStringPairs - 1 - q] =
          count == 2 && FitsStrings(*notes, kStringPairs - q) ? *notes : PairOnStrings(q);
    }
  }
  return count;
}

// The free analysis of Analyze (the header's steps (1)-(5)) on magnitude_.
int DoubleStopAnalyzer::FreePair(std::array<PolyNote, 2>* notes) {
  const Best first = Search(magnitude_, -1);
  if (first.index < 0) return 0;
  PolyNote one{Refine(first.index, magnitude_), first.salience};
  residual_ = magnitude_;
  const double own_salience = Cancel(first.index);
  const Best second = Search(residual_, first.index);
  if (second.index < 0 || second.salience < options_.second_min_ratio * own_salience) {
    (*notes)[0] = one;
    return 1;
  }
  PolyNote two{Refine(second.index, residual_), second.salience};
  // (5) One low note heard as its 2nd and 3rd partials (a fifth): D2 with a fundamental at
  // 9% of its 3rd partial read as D3 + A3.
  const int low =
      candidates_hz_[first.index] < candidates_hz_[second.index] ? first.index : second.index;
  const int single = PartialFifth(low, first.index == low ? second.index : first.index);
  if (single >= 0) {
    (*notes)[0] = PolyNote{Refine(single, magnitude_), Salience(single, magnitude_)};
    return 1;
  }
  // (4) A lost fundamental: a note whose own fundamental is weak is heard as its 2nd
  // partial, an octave too high, when the partner's cancellation leaves that partial the
  // strongest (a sixth B3 + G#4 read as G#4 + B4). Look at each note's octave below on the
  // spectrum without the partner: its odd partials belong to no note of the pair.
  for (int which = 0; which < 2; ++which) {
    const int note = which == 0 ? first.index : second.index;
    const int partner = which == 0 ? second.index : first.index;
    const int below = LostFundamental(note, partner);
    if (below < 0) continue;
    const PolyNote lower{Refine(below, residual_), Salience(below, residual_)};
    (which == 0 ? one : two) = lower;
    break;
  }
  if (two.f0_hz < one.f0_hz) std::swap(one, two);
  (*notes)[0] = one;
  (*notes)[1] = two;
  return 2;
}

// What Cancel(c) would take from `spectrum`, unweighted: per partial m, its main lobe's
// magnitudes times the share min(A_m, sqrt(A_{m-1} A_{m+1})) / A_m that is this note's.
// Unlike the salience (eq. 3 weighs a high note's partials more), it compares pairs of
// different notes on one scale: the spectrum each pair accounts for.
double DoubleStopAnalyzer::Explained(int c, const std::vector<double>& spectrum) const {
  const int harmonics = options_.harmonics;
  std::array<double, 64> amplitude{};
  std::array<int, 64> at{};
  int count = 0;
  for (int m = 1; m <= harmonics && m + 1 < static_cast<int>(amplitude.size()); ++m) {
    const double a = BandMax(c, m, spectrum, &at[m]);
    if (a < 0) break;
    amplitude[m] = a;
    count = m;
  }
  double explained = 0;
  for (int m = 1; m <= count; ++m) {
    if (!(amplitude[m] > 0)) continue;
    // Only a partial that is there: the band's maximum a peak, not the slope of a
    // neighbour's (whose lobe it would count as its own: a semitone above the cello's
    // C2, C#2's bands lie on C2's partials' slopes).
    const int k = at[m];
    const bool peak = (k == 0 || spectrum[k - 1] <= spectrum[k]) &&
                      (k + 1 >= static_cast<int>(spectrum.size()) || spectrum[k + 1] <= spectrum[k]);
    if (!peak) continue;
    const double own = OwnAmplitude(amplitude.data(), m, count);
    const int lo = std::max(0, at[m] - lobe_bins_), hi = std::min(fft_size_ / 2, at[m] + lobe_bins_);
    double lobe = 0;
    for (int k = lo; k <= hi; ++k) lobe += spectrum[k];
    explained += own / amplitude[m] * lobe;
  }
  return explained;
}

bool DoubleStopAnalyzer::FitsStrings(const std::array<PolyNote, 2>& pair, int upper_string) const {
  if (!has_strings_ || upper_string < 1 || upper_string > kStringPairs) return false;
  if (!(pair[0].f0_hz > 0 && pair[1].f0_hz > 0)) return false;
  const int q = kStringPairs - upper_string;  // the lower string, low to high
  const double low = 69.0 + 12.0 * std::log2(pair[0].f0_hz / options_.a4_hz) - open_midi_[q];
  const double high = 69.0 + 12.0 * std::log2(pair[1].f0_hz / options_.a4_hz) - open_midi_[q + 1];
  return low >= -0.5 && low <= kPairMaxStopSemitones && high >= -0.5 &&
         high <= kPairMaxStopSemitones && std::abs(high - low) <= options_.max_span_semitones;
}

// The pair with one note on each of two adjacent strings (open_midi_[q] below,
// open_midi_[q + 1] above) that explains most of the spectrum: for each string taken
// first, its kPairFirstCandidates most salient candidates (at least kMinIntervalSemitones
// apart, their fundamentals present), each cancelled from the spectrum and joined by the
// candidate of the other string that explains most of the residual and makes a playable
// pair with it (its fundamental present on the residual, but for an octave above, whose
// fundamental is the lower note's 2nd partial); the pair that explains most in all
// (Explained, unweighted: with the salience's weights the cello's C3 + G3 on its C and G
// strings outscored the open C2 + C3 whose partials they are). Greedy free analysis
// (FreePair) takes the loudest candidate anywhere first, so a partial of the pair or a
// ghost an octave away is often its first note; here every note is where the strings put
// it (the double bass's D2 + B2 freely heard as B1 + D2, the viola's E3 + E4 as E4 + B4).
// Stops from the nut up to kPairMaxStopSemitones.
std::array<PolyNote, 2> DoubleStopAnalyzer::PairOnStrings(int q) {
  const std::array<double, 2> open = {open_midi_[q], open_midi_[q + 1]};
  const double peak = *std::max_element(magnitude_.begin(), magnitude_.end());
  const double min_fundamental = kPairFundamentalShare * options_.min_fundamental_ratio * peak;
  const int n = static_cast<int>(candidates_hz_.size());
  double best_score = 0;
  int best_first = -1, best_second = -1;
  for (int first_string = 0; first_string < 2; ++first_string) {
    const double open_first = open[first_string], open_second = open[1 - first_string];
    // The first string's most salient candidates, one per semitone's neighbourhood.
    std::vector<std::pair<double, int>> ranked;
    for (int c = 0; c < n; ++c) {
      const double stop = candidates_midi_[c] - open_first;
      if (stop < -0.5 || stop > kPairMaxStopSemitones) continue;
      if (Fundamental(c, magnitude_) < min_fundamental) continue;
      ranked.push_back({Salience(c, magnitude_), c});
    }
    std::sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) {
      return a.first > b.first || (a.first == b.first && a.second < b.second);
    });
    std::vector<int> firsts;
    for (const auto& [salience, c] : ranked) {
      if (static_cast<int>(firsts.size()) == kPairFirstCandidates) break;
      bool near = false;
      for (const int f : firsts) {
        near |= std::abs(candidates_midi_[f] - candidates_midi_[c]) < kMinIntervalSemitones;
      }
      if (!near) firsts.push_back(c);
    }
    for (const int c1 : firsts) {
      residual_ = magnitude_;
      const double own = Explained(c1, magnitude_);
      Cancel(c1);
      const double stop_first = candidates_midi_[c1] - open_first;
      double best_s2 = 0;
      int c2_best = -1;
      for (int c2 = 0; c2 < n; ++c2) {
        const double m2 = candidates_midi_[c2];
        if (m2 < open_second - 0.5 || m2 - open_second > kPairMaxStopSemitones) continue;
        if (std::abs(m2 - candidates_midi_[c1]) < kMinIntervalSemitones) continue;
        // The lower string's note must be the lower note.
        if ((first_string == 0) != (candidates_midi_[c1] < m2)) continue;
        if (std::abs((m2 - open_second) - stop_first) > options_.max_span_semitones) continue;
        const bool octave_above = first_string == 0 &&
                                  std::abs(m2 - candidates_midi_[c1] - 12.0) < kPartialCents / 100.0;
        if (!octave_above && Fundamental(c2, residual_) < min_fundamental) continue;
        const double s2 = Explained(c2, residual_);
        if (s2 > best_s2) {
          best_s2 = s2;
          c2_best = c2;
        }
      }
      if (c2_best < 0 || own + best_s2 <= best_score) continue;
      best_score = own + best_s2;
      best_first = c1;
      best_second = c2_best;
    }
  }
  if (best_first < 0) return {};
  residual_ = magnitude_;
  Cancel(best_first);
  // The f0 refined from the partials, where it stays within the candidate's partial band:
  // an octave's lower note shares every even partial with the upper one, and its fit was
  // pulled a semitone off (the cello's open C2 under C3 refined to 69.5 Hz on 5 of 23
  // frames), which a single note's fit never is.
  const auto refined = [&](int c, const std::vector<double>& spectrum) {
    const double f0 = Refine(c, spectrum);
    return std::abs(1200.0 * std::log2(f0 / candidates_hz_[c])) <= kPartialCents
               ? f0
               : candidates_hz_[c];
  };
  PolyNote one{refined(best_first, magnitude_), Salience(best_first, magnitude_)};
  PolyNote two{refined(best_second, residual_), Salience(best_second, residual_)};
  if (two.f0_hz < one.f0_hz) std::swap(one, two);
  return {one, two};
}

namespace {

// Semitones on the MIDI scale at A4 = 440 Hz: only intervals and same-pair keys are taken
// from it, so the take's tuning plays no part.
double MidiOf(double f0_hz) { return 69.0 + 12.0 * std::log2(f0_hz / 440.0); }

// A pair's notes as the nearest semitones (the same pair on two frames has the same key).
std::array<int64_t, 2> PairKey(const PolyPitchFrame& f) {
  return {std::llround(MidiOf(f.notes[0].f0_hz)), std::llround(MidiOf(f.notes[1].f0_hz))};
}

// Whether every note of `heard` is a note of `pair` or its 2nd, 3rd or 4th partial (within
// half a semitone; fractional MIDI pitches).
bool ExplainedBy(const PolyPitchFrame& pair, const PolyPitchFrame& heard) {
  for (int n = 0; n < 2; ++n) {
    const double q = MidiOf(heard.notes[n].f0_hz);
    bool explained = false;
    for (int k = 0; k < 2 && !explained; ++k) {
      const double base = MidiOf(pair.notes[k].f0_hz);
      for (int h = 1; h <= 4 && !explained; ++h)
        explained = std::abs(q - base - 12.0 * std::log2(static_cast<double>(h))) <= 0.5;
    }
    if (!explained) return false;
  }
  return true;
}

}  // namespace

void ConsistentDoubleStops(int window_frames, std::vector<PolyPitchFrame>* frames) {
  if (window_frames <= 0) return;
  const std::vector<PolyPitchFrame> heard = *frames;
  const int64_t n = static_cast<int64_t>(heard.size());
  auto is_pair = [&](int64_t j) {
    return heard[j].count == 2 && heard[j].notes[0].f0_hz > 0 && heard[j].notes[1].f0_hz > 0;
  };
  for (int64_t i = 0; i < n; ++i) {
    if (!is_pair(i)) continue;
    const auto own = PairKey(heard[i]);
    const int64_t lo = std::max<int64_t>(0, i - window_frames);
    const int64_t hi = std::min<int64_t>(n - 1, i + window_frames);
    int own_support = 0;  // frames of the window (i included) that heard i's own pair
    for (int64_t k = lo; k <= hi; ++k) own_support += is_pair(k) && PairKey(heard[k]) == own;
    int64_t best = -1;  // nearest frame of the chosen pair
    int best_support = 0;
    std::array<int64_t, 2> best_key{};
    // Candidates in order of distance from i (earlier first on a tie), so the first frame
    // of each key met is its nearest.
    for (int64_t d = 1; d <= window_frames; ++d) {
      for (const int64_t j : {i - d, i + d}) {
        if (j < lo || j > hi || !is_pair(j)) continue;
        const auto key = PairKey(heard[j]);
        if (key == own || !ExplainedBy(heard[j], heard[i])) continue;
        bool before = false, after = false;
        int support = 0;
        for (int64_t k = lo; k <= hi; ++k) {
          if (!is_pair(k) || PairKey(heard[k]) != key) continue;
          ++support;
          before |= k < i;
          after |= k > i;
        }
        if (!before || !after || 2 * support < own_support) continue;
        if (support > best_support || (support == best_support && key < best_key)) {
          best = j;
          best_support = support;
          best_key = key;
        }
      }
    }
    if (best >= 0) {
      (*frames)[i].notes = heard[best].notes;
      (*frames)[i].count = 2;
    }
  }
}

std::vector<double> SecondNoteHz(const std::vector<PitchFrame>& frames,
                                 const std::vector<PolyPitchFrame>& poly,
                                 double match_cents) {
  std::vector<double> second(frames.size(), 0.0);
  for (size_t i = 0; i < frames.size() && i < poly.size(); ++i) {
    const PitchFrame& f = frames[i];
    const PolyPitchFrame& p = poly[i];
    if (!f.voiced || f.f0_hz <= 0 || p.count < 2) continue;
    for (int j = 0; j < 2; ++j) {
      const double cents = 1200.0 * std::log2(p.notes[j].f0_hz / f.f0_hz);
      if (std::abs(cents) <= match_cents) {
        second[i] = p.notes[1 - j].f0_hz;
        break;
      }
    }
  }
  return second;
}

NoteAnalysis SecondVoiceNotes(const std::vector<PitchFrame>& frames,
                              const std::vector<double>& second_f0_hz,
                              double fps,
                              const NoteOptions& options) {
  std::vector<PitchFrame> voice = frames;
  for (size_t i = 0; i < voice.size(); ++i) {
    const double f0 = i < second_f0_hz.size() ? second_f0_hz[i] : 0.0;
    voice[i].voiced = f0 > 0;
    voice[i].f0_hz = f0;
  }
  NoteAnalysis notes = SegmentNotes(voice, fps, options);
  notes.glides.clear();  // a second voice's glides are not told apart from its notes' edges
  return notes;
}

StatusOr<std::vector<PolyPitchFrame>> TrackDoubleStops(std::unique_ptr<AudioReader> reader,
                                                       const DoubleStopOptions& options,
                                                       DoubleStopSummary* summary) {
  const std::clock_t cpu_start = std::clock();
  ARCO_RETURN_IF_ERROR(options.Validate());
  DoubleStopAnalyzer analyzer(options);
  const double rate = options.range.analysis_rate_hz;
  SampleStream stream(std::move(reader), options.range.analysis_rate_hz);
  const int window = analyzer.window_length();
  std::vector<float> buffer(static_cast<size_t>(window));
  std::vector<PolyPitchFrame> frames;
  ARCO_ASSIGN_OR_RETURN(const bool has_audio, stream.Has(0));
  for (int64_t i = 0; has_audio && (options.max_frames < 0 || i < options.max_frames); ++i) {
    // Time from i directly, window centred on the nearest sample (as the tracker).
    const double time_s = options.start_s + static_cast<double>(i) / options.fps;
    const int64_t centre = std::llround(time_s * rate);
    if (centre >= 0) {
      ARCO_ASSIGN_OR_RETURN(const bool inside, stream.Has(centre));
      if (!inside) break;
    }
    ARCO_RETURN_IF_ERROR(stream.Read(centre - window / 2, window, buffer.data()));
    PolyPitchFrame f;
    f.frame = i;
    f.time_s = time_s;
    f.count = analyzer.Analyze(buffer.data(), &f.notes, &f.on_strings);
    frames.push_back(f);
  }
  ConsistentDoubleStops(static_cast<int>(std::llround(options.consistency_s * options.fps)),
                        &frames);
  // The free pair made consistent over time is the pair on any strings it fits, as the
  // frame's own free pair was (Analyze): a frame alone heard the double bass's E1 + C#2 as
  // C#2 + E2 and G#1 + D#2 as D#2 + G#2, which its neighbours' pair explains.
  for (PolyPitchFrame& f : frames) {
    for (int s = 0; s < kStringPairs; ++s) {
      if (f.count == 2 && analyzer.FitsStrings(f.notes, s + 1)) f.on_strings[s] = f.notes;
    }
  }
  if (summary != nullptr) {
    *summary = DoubleStopSummary();
    summary->frames = static_cast<int64_t>(frames.size());
    for (const auto& f : frames) {
      (f.count == 0 ? summary->silent_frames
                    : (f.count == 1 ? summary->single_frames : summary->double_frames))++;
    }
    summary->cpu_seconds = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  }
  return frames;
}

StatusOr<std::vector<PolyPitchFrame>> TrackDoubleStopsFile(const std::string& path,
                                                           const DoubleStopOptions& options,
                                                           DoubleStopSummary* summary) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  ARCO_ASSIGN_OR_RETURN(auto reader, OpenAudio(path));
  return TrackDoubleStops(std::move(reader), options, summary);
}

}  // namespace arco::audio
