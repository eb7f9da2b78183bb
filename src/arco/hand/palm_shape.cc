#include "arco/hand/palm_shape.h"

#include <cmath>
#include <sstream>

#include "arco/geometry/rotation.h"
#include "arco/util/stats.h"

namespace arco::hand {
namespace {

constexpr int kPalmPoints = 1 + kNumFingers;  // the wrist, then the five bases

int PalmKeypoint(int i) { return i == 0 ? 0 : KeypointIndex(static_cast<Finger>(i - 1), 0); }

using Palm = std::array<Eigen::Vector3d, kPalmPoints>;

Eigen::Vector3d Centroid(const Palm& p) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& x : p) c += x;
  return c / kPalmPoints;
}

// `x` moved rigidly onto `target` (least squares, Kabsch 1976); `rms_mm` its residual.
Palm AlignOnto(const Palm& x, const Palm& target, double* rms_mm) {
  const Eigen::Vector3d cx = Centroid(x), ct = Centroid(target);
  std::vector<Eigen::Vector3d> a(kPalmPoints), b(kPalmPoints);
  for (int i = 0; i < kPalmPoints; ++i) {
    a[static_cast<size_t>(i)] = x[static_cast<size_t>(i)] - cx;
    b[static_cast<size_t>(i)] = target[static_cast<size_t>(i)] - ct;
  }
  const Eigen::Matrix3d r = KabschRotation(a, b);
  Palm y;
  double sum = 0;
  for (int i = 0; i < kPalmPoints; ++i) {
    y[static_cast<size_t>(i)] = r * a[static_cast<size_t>(i)] + ct;
    sum += (y[static_cast<size_t>(i)] - target[static_cast<size_t>(i)]).squaredNorm();
  }
  *rms_mm = std::sqrt(sum / kPalmPoints);
  return y;
}

}  // namespace

Status PalmShapeOptions::Validate() const {
  if (min_frames < 1) return Status::Error("palm: min_frames must be >= 1");
  if (rounds < 1 || rounds > 20) return Status::Error("palm: rounds must be in [1, 20]");
  if (!(gate > 0) || !std::isfinite(gate)) return Status::Error("palm: gate must be > 0");
  if (!(max_shift_mm >= 0) || !std::isfinite(max_shift_mm)) {
    return Status::Error("palm: max_shift_mm must be a finite value >= 0");
  }
  return Status::Ok();
}

StatusOr<PalmShapeEstimate> EstimatePalmShape(const std::vector<HandPointsMm>& frames,
                                              const HandModel& model,
                                              const PalmShapeOptions& options) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  Palm model_palm;
  for (int i = 0; i < kPalmPoints; ++i) {
    model_palm[static_cast<size_t>(i)] = model.rest_point_mm(PalmKeypoint(i));
  }
  std::vector<Palm> samples;
  for (const HandPointsMm& f : frames) {
    Palm p;
    bool finite = true;
    for (int i = 0; i < kPalmPoints; ++i) {
      p[static_cast<size_t>(i)] = f[static_cast<size_t>(PalmKeypoint(i))];
      finite = finite && p[static_cast<size_t>(i)].allFinite();
    }
    if (finite) samples.push_back(p);
  }
  const auto too_few = [&](size_t n) {
    std::ostringstream msg;
    msg << "palm: " << n << " frames show the wrist and all five finger bases ("
        << options.min_frames << " needed)";
    return Status::Error(msg.str());
  };
  if (static_cast<int>(samples.size()) < options.min_frames) return too_few(samples.size());

  Palm mean = model_palm;
  std::vector<Palm> aligned(samples.size());
  std::vector<double> rms(samples.size());
  std::vector<uint8_t> kept(samples.size(), 0);
  PalmShapeEstimate out;
  for (int round = 0; round < options.rounds; ++round) {
    for (size_t s = 0; s < samples.size(); ++s) aligned[s] = AlignOnto(samples[s], mean, &rms[s]);
    // Gate on the residual: frames with an outlier point or a swapped detection.
    const double med = Median(rms);
    std::vector<double> dev(rms.size());
    for (size_t s = 0; s < rms.size(); ++s) dev[s] = std::abs(rms[s] - med);
    const double sigma = std::max(1.4826 * Median(dev), 0.1);
    int used = 0;
    for (size_t s = 0; s < rms.size(); ++s) {
      kept[s] = rms[s] <= med + options.gate * sigma;
      used += kept[s];
    }
    if (used < options.min_frames) return too_few(static_cast<size_t>(used));
    std::vector<double> values;
    values.reserve(static_cast<size_t>(used));
    for (int i = 0; i < kPalmPoints; ++i) {
      for (int c = 0; c < 3; ++c) {
        values.clear();
        for (size_t s = 0; s < aligned.size(); ++s) {
          if (kept[s]) values.push_back(aligned[s][static_cast<size_t>(i)][c]);
        }
        mean[static_cast<size_t>(i)][c] = Median(values);
      }
    }
    out.frames_used = used;
  }
  std::vector<double> kept_rms;
  for (size_t s = 0; s < samples.size(); ++s) {
    double r = 0;
    AlignOnto(samples[s], mean, &r);
    if (kept[s]) kept_rms.push_back(r);
  }
  out.median_residual_mm = Median(kept_rms);
  // About the mean's wrist, turned onto the model's bases (the model's wrist frame).
  std::vector<Eigen::Vector3d> a(kNumFingers), b(kNumFingers);
  for (int f = 0; f < kNumFingers; ++f) {
    a[static_cast<size_t>(f)] = mean[static_cast<size_t>(f + 1)] - mean[0];
    b[static_cast<size_t>(f)] = model_palm[static_cast<size_t>(f + 1)];  // the wrist is 0
  }
  const Eigen::Matrix3d r = KabschRotation(a, b);
  for (int f = 0; f < kNumFingers; ++f) {
    const Eigen::Vector3d base = r * a[static_cast<size_t>(f)];
    const double shift = (base - b[static_cast<size_t>(f)]).norm();
    out.shift_mm[static_cast<size_t>(f)] = shift;
    out.kept_model[static_cast<size_t>(f)] = shift > options.max_shift_mm;
    out.base_in_wrist_mm[static_cast<size_t>(f)] =
        out.kept_model[static_cast<size_t>(f)] ? b[static_cast<size_t>(f)] : base;
  }
  return out;
}

}  // namespace arco::hand
