#include "arco/hand/bone_lengths.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "arco/util/stats.h"

namespace arco::hand {
namespace {}  // namespace

Status BoneLengthOptions::Validate() const {
  auto bad = [](const std::string& m) { return Status::Error("BoneLengthOptions: " + m); };
  if (min_samples < 1) return bad("min_samples must be >= 1");
  if (!(mad_gate > 0)) return bad("mad_gate must be > 0");
  if (!(min_mad_mm >= 0)) return bad("min_mad_mm must be >= 0");
  if (!(min_ratio > 0 && min_ratio <= 1 && max_ratio >= 1 && std::isfinite(max_ratio))) {
    return bad("need 0 < min_ratio <= 1 <= max_ratio");
  }
  if (!(quantile >= 0.5 && quantile < 1)) return bad("quantile must be in [0.5, 1)");
  if (!(palm_quantile >= 0.5 && palm_quantile < 1)) return bad("palm_quantile must be in [0.5, 1)");
  if (!(thumb_quantile >= 0.5 && thumb_quantile < 1))
    return bad("thumb_quantile must be in [0.5, 1)");
  return Status::Ok();
}

StatusOr<BoneLengthEstimate> EstimateBoneLengths(const std::vector<HandPointsMm>& frames,
                                                 const HandModel& prior,
                                                 const BoneLengthOptions& options) {
  const Status valid = options.Validate();
  if (!valid.ok()) throw std::invalid_argument(valid.message());
  BoneLengthEstimate out;
  std::vector<double> ratios;
  std::vector<double> samples;
  samples.reserve(frames.size());
  for (int k = 1; k < kNumHandKeypoints; ++k) {
    const int parent = ParentKeypoint(k);
    const double prior_mm = prior.bone_length_mm(k);
    samples.clear();
    for (const HandPointsMm& f : frames) {
      if (!f[k].allFinite() || !f[parent].allFinite()) continue;
      const double d = (f[k] - f[parent]).norm();
      if (d >= 0.3 * prior_mm && d <= 3.0 * prior_mm) samples.push_back(d);
    }
    out.samples[k] = static_cast<int>(samples.size());
    if (out.samples[k] < options.min_samples) continue;
    const double median = Median(samples);
    const double sigma =
        std::max(kMadToSigma * MedianAbsDeviation(samples, median), options.min_mad_mm);
    std::vector<double> inliers;
    for (double d : samples) {
      if (std::abs(d - median) <= options.mad_gate * sigma) inliers.push_back(d);
    }
    out.inliers[k] = static_cast<int>(inliers.size());
    const bool thumb = k <= KeypointIndex(Finger::kThumb, 3);
    const bool palm = !thumb && parent == 0;
    const double q = thumb  ? options.thumb_quantile
                     : palm ? options.palm_quantile
                            : options.quantile;
    const double m = q == 0.5 ? Median(inliers) : InterpolatedQuantile(inliers, q);
    out.lengths_mm[k] = m;
    if (options.correct_noise_bias) {
      const double tau = kMadToSigma * MedianAbsDeviation(inliers, m);
      // At most half the median: a spread comparable with the bone says the
      // samples are noise, and the prior bounds below take over.
      out.lengths_mm[k] = m - std::min(tau * tau / m, 0.5 * m);
    }
    out.from_data[k] = 1;
    ratios.push_back(out.lengths_mm[k] / prior_mm);
  }
  if (ratios.empty()) {
    std::ostringstream msg;
    msg << "bone lengths: no bone has " << options.min_samples
        << " frames with both keypoints triangulated (" << frames.size() << " frames)";
    return Status::Error(msg.str());
  }
  if (options.palm_as_one) {
    // The middle two of the four palm bones' ratios (header comment); all four measured.
    std::vector<double> palm;
    for (int f = static_cast<int>(Finger::kIndex); f <= static_cast<int>(Finger::kLittle); ++f) {
      const int k = KeypointIndex(static_cast<Finger>(f), 0);
      if (out.from_data[k]) palm.push_back(out.lengths_mm[k] / prior.bone_length_mm(k));
    }
    if (palm.size() == 4) {
      std::sort(palm.begin(), palm.end());
      const double scale = 0.5 * (palm[1] + palm[2]);
      for (int f = static_cast<int>(Finger::kIndex); f <= static_cast<int>(Finger::kLittle); ++f) {
        const int k = KeypointIndex(static_cast<Finger>(f), 0);
        out.lengths_mm[k] = scale * prior.bone_length_mm(k);
      }
    }
  }
  out.hand_scale = Median(ratios);
  if (out.hand_scale < options.min_ratio || out.hand_scale > options.max_ratio) {
    std::ostringstream msg;
    msg << "bone lengths: the hand measures " << out.hand_scale
        << " x an average adult hand; are the world units millimetres?";
    return Status::Error(msg.str());
  }
  for (int k = 1; k < kNumHandKeypoints; ++k) {
    const double prior_mm = prior.bone_length_mm(k);
    if (!out.from_data[k]) out.lengths_mm[k] = out.hand_scale * prior_mm;
    const double clamped =
        std::clamp(out.lengths_mm[k], options.min_ratio * prior_mm, options.max_ratio * prior_mm);
    out.clamped[k] = clamped != out.lengths_mm[k];
    out.lengths_mm[k] = clamped;
  }
  return out;
}

}  // namespace arco::hand
