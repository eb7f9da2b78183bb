#include "arco/instrument/pose_smoothing.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "arco/geometry/rotation.h"

namespace arco {

Status PoseSmoothingOptions::Validate() const {
  if (!std::isfinite(sigma_frames) || sigma_frames <= 0) {
    return Status::Error("pose smoothing: sigma_frames must be > 0");
  }
  if (radius_frames < 0) return Status::Error("pose smoothing: radius_frames must be >= 0");
  if (max_fill_gap_frames < 0) {
    return Status::Error("pose smoothing: max_fill_gap_frames must be >= 0");
  }
  if (max_end_hold_frames < 0) {
    return Status::Error("pose smoothing: max_end_hold_frames must be >= 0");
  }
  return Status::Ok();
}

std::vector<InstrumentFramePose> SmoothFramePoses(const std::vector<InstrumentFramePose>& frames,
                                                  const PoseSmoothingOptions& options) {
  const Status status = options.Validate();
  if (!status.ok()) throw std::invalid_argument(status.message());
  const int n = static_cast<int>(frames.size());
  const int radius = options.radius_frames > 0
                         ? options.radius_frames
                         : static_cast<int>(std::ceil(3.0 * options.sigma_frames));
  std::vector<double> kernel(radius + 1);
  for (int d = 0; d <= radius; ++d) {
    kernel[d] = std::exp(-0.5 * d * d / (options.sigma_frames * options.sigma_frames));
  }
  std::vector<Eigen::Quaterniond> quats(n);
  std::vector<int> prev_ok(n, -1), next_ok(n, -1);
  for (int f = 0, last = -1; f < n; ++f) {
    if (frames[f].status == FrameFitStatus::kOk) {
      quats[f] = Eigen::Quaterniond(frames[f].world_from_instrument.rotation).normalized();
      last = f;
    }
    prev_ok[f] = last;
  }
  for (int f = n - 1, next = -1; f >= 0; --f) {
    if (frames[f].status == FrameFitStatus::kOk) next = f;
    next_ok[f] = next;
  }

  std::vector<InstrumentFramePose> out = frames;
  for (int f = 0; f < n; ++f) {
    const InstrumentFramePose& in = frames[f];
    if (in.status == FrameFitStatus::kTooFewPoints) {
      // Fill gaps bounded by kOk frames on both sides within the limit, and the clip's
      // ends within theirs.
      const bool gap = prev_ok[f] >= 0 && next_ok[f] >= 0 && options.max_fill_gap_frames > 0 &&
                       next_ok[f] - prev_ok[f] - 1 <= options.max_fill_gap_frames;
      const bool start = prev_ok[f] < 0 && next_ok[f] >= 0 &&
                         next_ok[f] - f <= options.max_end_hold_frames;
      const bool end = next_ok[f] < 0 && prev_ok[f] >= 0 &&
                       f - prev_ok[f] <= options.max_end_hold_frames;
      if (!gap && !start && !end) continue;
    } else if (in.status == FrameFitStatus::kHighResidual && !options.replace_high_residual) {
      continue;
    }
    std::vector<Eigen::Quaterniond> window;
    std::vector<double> weights;
    Eigen::Vector3d translation = Eigen::Vector3d::Zero();
    double weight_sum = 0;
    double units = 0;
    for (int g = std::max(0, f - radius); g <= std::min(n - 1, f + radius); ++g) {
      if (frames[g].status != FrameFitStatus::kOk) continue;
      const double w = kernel[std::abs(g - f)];
      window.push_back(quats[g]);
      weights.push_back(w);
      translation += w * frames[g].world_from_instrument.translation;
      units = frames[g].world_from_instrument.scale;
      weight_sum += w;
    }
    if (weight_sum <= 0) continue;
    const std::optional<Eigen::Quaterniond> mean = AverageQuaternions(window, weights);
    if (!mean) continue;
    out[f].filled = in.status != FrameFitStatus::kOk;
    out[f].status = FrameFitStatus::kOk;
    out[f].world_from_instrument =
        SimMatrix3d(units, mean->normalized().toRotationMatrix(), translation / weight_sum);
  }
  return out;
}

double LeaveOneOutSigmaFrames(const std::vector<InstrumentFramePose>& frames,
                              const std::vector<Eigen::Vector3d>& probe_points_in_instrument,
                              const std::vector<double>& candidates_frames,
                              int min_frames) {
  if (candidates_frames.empty())
    throw std::invalid_argument("LeaveOneOutSigmaFrames: no candidates");
  for (double c : candidates_frames) {
    if (!(c > 0) || !std::isfinite(c))
      throw std::invalid_argument("LeaveOneOutSigmaFrames: candidates must be finite and > 0");
  }
  const int n = static_cast<int>(frames.size());
  const int probes = static_cast<int>(probe_points_in_instrument.size());
  // Each kOk frame's probes in the world, stacked (frame-major).
  std::vector<uint8_t> ok(n, 0);
  std::vector<Eigen::Vector3d> placed(static_cast<size_t>(n) * probes);
  int posed = 0;
  for (int f = 0; f < n; ++f) {
    if (frames[f].status != FrameFitStatus::kOk) continue;
    ok[f] = 1;
    ++posed;
    for (int p = 0; p < probes; ++p) {
      placed[static_cast<size_t>(f) * probes + p] =
          frames[f].world_from_instrument * probe_points_in_instrument[p];
    }
  }
  if (posed < min_frames || probes == 0) return candidates_frames[0];
  double best = candidates_frames[0];
  double best_error = std::numeric_limits<double>::infinity();
  std::vector<Eigen::Vector3d> mean(probes);
  for (double sigma : candidates_frames) {
    // The kernel as SmoothFramePoses builds it (radius ceil(3 sigma)).
    const int radius = static_cast<int>(std::ceil(3.0 * sigma));
    std::vector<double> kernel(radius + 1);
    for (int d = 0; d <= radius; ++d) kernel[d] = std::exp(-0.5 * d * d / (sigma * sigma));
    double sum = 0;
    int count = 0;
    for (int f = 0; f < n; ++f) {
      if (!ok[f]) continue;
      double wsum = 0;
      std::fill(mean.begin(), mean.end(), Eigen::Vector3d::Zero());
      for (int g = std::max(0, f - radius); g <= std::min(n - 1, f + radius); ++g) {
        if (g == f || !ok[g]) continue;
        const double w = kernel[std::abs(g - f)];
        wsum += w;
        for (int p = 0; p < probes; ++p) mean[p] += w * placed[static_cast<size_t>(g) * probes + p];
      }
      if (!(wsum > 0)) continue;
      for (int p = 0; p < probes; ++p)
        sum += (mean[p] / wsum - placed[static_cast<size_t>(f) * probes + p]).squaredNorm();
      ++count;
    }
    const double error = count > 0 ? sum / count : std::numeric_limits<double>::infinity();
    if (error < best_error) {
      best_error = error;
      best = sigma;
    }
  }
  return best;
}

}  // namespace arco
