#include "arco/mocap/temporal_filter.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace arco {
namespace {

struct Biquad {
  double b0, b1, b2, a1, a2;  // a0 = 1
};

// Digital Butterworth low-pass as second-order sections. Analog prototype
// 1 / prod(s'^2 + 2 sin(theta_k) s' + 1) (times 1 / (s' + 1) for odd orders), with
// s' = (z - 1) / (K (z + 1)), K = tan(pi fc / fs) (bilinear transform, prewarped).
std::vector<Biquad> DesignButterworth(int order, double cutoff_hz, double fps) {
  const double k = std::tan(M_PI * cutoff_hz / fps);
  const double k2 = k * k;
  std::vector<Biquad> sections;
  for (int i = 0; i < order / 2; ++i) {
    const double c = 2 * std::sin(M_PI * (2 * i + 1) / (2.0 * order));
    const double a0 = 1 + c * k + k2;
    sections.push_back({k2 / a0, 2 * k2 / a0, k2 / a0, (2 * k2 - 2) / a0, (1 - c * k + k2) / a0});
  }
  if (order % 2 == 1) {
    const double a0 = 1 + k;
    sections.push_back({k / a0, k / a0, 0, (k - 1) / a0, 0});
  }
  return sections;
}

// Runs the cascade over x (transposed direct form II) starting in the steady state
// for a constant input equal to x[0].
void RunCascade(const std::vector<Biquad>& sections, std::vector<double>* x) {
  if (x->empty()) return;
  double input_level = (*x)[0];
  for (const Biquad& s : sections) {
    const double gain = (s.b0 + s.b1 + s.b2) / (1 + s.a1 + s.a2);
    const double y_ss = gain * input_level;
    double z2 = s.b2 * input_level - s.a2 * y_ss;
    double z1 = y_ss - s.b0 * input_level;
    for (double& v : *x) {
      const double in = v;
      const double out = s.b0 * in + z1;
      z1 = s.b1 * in - s.a1 * out + z2;
      z2 = s.b2 * in - s.a2 * out;
      v = out;
    }
    input_level = y_ss;
  }
}

void ButterworthFiltFilt(const TemporalFilterOptions& o, double fps, double* x, int n) {
  if (n < 2) return;
  const auto sections = DesignButterworth(o.order, o.cutoff_hz, fps);
  const int pad = std::min(3 * (2 * static_cast<int>(sections.size()) + 1), n - 1);
  std::vector<double> ext;
  ext.reserve(static_cast<size_t>(n + 2 * pad));
  for (int i = pad; i >= 1; --i) ext.push_back(2 * x[0] - x[i]);  // odd extension
  ext.insert(ext.end(), x, x + n);
  for (int i = n - 2; i >= n - 1 - pad; --i) ext.push_back(2 * x[n - 1] - x[i]);
  RunCascade(sections, &ext);
  std::reverse(ext.begin(), ext.end());
  RunCascade(sections, &ext);
  std::reverse(ext.begin(), ext.end());
  std::copy(ext.begin() + pad, ext.begin() + pad + n, x);
}

// Row i: weights that give the fitted polynomial's value at window position i.
Eigen::MatrixXd SavitzkyGolayWeights(int window, int polyorder) {
  const int half = window / 2;
  Eigen::MatrixXd a(window, polyorder + 1);
  for (int i = 0; i < window; ++i) {
    const double t =
        half > 0 ? static_cast<double>(i - half) / half : 0.0;  // scaled for conditioning
    double p = 1;
    for (int j = 0; j <= polyorder; ++j, p *= t) a(i, j) = p;
  }
  // Least squares: coefficients = (A^T A)^-1 A^T y; values at the window = A coefficients.
  const Eigen::MatrixXd pinv = (a.transpose() * a).ldlt().solve(a.transpose());
  return a * pinv;
}

void SavitzkyGolay(const TemporalFilterOptions& o, double* x, int n) {
  int window = std::min(o.window, n % 2 == 1 ? n : n - 1);
  const int polyorder = std::min(o.polyorder, window - 1);
  if (window < 3) return;
  const Eigen::MatrixXd w = SavitzkyGolayWeights(window, polyorder);
  const int half = window / 2;
  std::vector<double> out(x, x + n);
  auto apply = [&](int row, int start) {
    double s = 0;
    for (int j = 0; j < window; ++j) s += w(row, j) * x[start + j];
    return s;
  };
  for (int i = 0; i < n; ++i) {
    if (i < half) {
      out[i] = apply(i, 0);
    } else if (i >= n - half) {
      out[i] = apply(window - (n - i), n - window);
    } else {
      out[i] = apply(half, i - half);
    }
  }
  std::copy(out.begin(), out.end(), x);
}

double OneEuroAlpha(double cutoff_hz, double fps) {
  const double tau = 1.0 / (2 * M_PI * cutoff_hz);
  return 1.0 / (1.0 + tau * fps);
}

void OneEuro(const TemporalFilterOptions& o, double fps, double* x, int n) {
  if (n < 2) return;
  double prev = x[0], dprev = 0;
  const double alpha_d = OneEuroAlpha(o.d_cutoff_hz, fps);
  for (int i = 1; i < n; ++i) {
    const double dx = (x[i] - prev) * fps;
    dprev = alpha_d * dx + (1 - alpha_d) * dprev;
    const double alpha = OneEuroAlpha(o.min_cutoff_hz + o.beta * std::abs(dprev), fps);
    prev = alpha * x[i] + (1 - alpha) * prev;
    x[i] = prev;
  }
}

}  // namespace

Status TemporalFilterOptions::Validate(double fps) const {
  auto bad = [](const std::string& m) { return Status::Error("filter options: " + m); };
  if (!(fps > 0 && std::isfinite(fps))) return bad("fps must be positive");
  if (max_gap_frames < 0) return bad("max_gap_frames must be >= 0");
  switch (kind) {
    case FilterKind::kNone:
      break;
    case FilterKind::kButterworth:
      if (!(cutoff_hz > 0 && cutoff_hz < 0.5 * fps)) {
        return bad("Butterworth cutoff_hz must be in (0, fps/2)");
      }
      if (order < 1 || order > 8) return bad("Butterworth order must be 1..8");
      break;
    case FilterKind::kSavitzkyGolay:
      if (window < 3 || window % 2 == 0) return bad("Savitzky-Golay window must be odd and >= 3");
      if (polyorder < 0 || polyorder >= window) {
        return bad("Savitzky-Golay polyorder must be in [0, window)");
      }
      break;
    case FilterKind::kOneEuro:
      if (!(min_cutoff_hz > 0 && min_cutoff_hz < 0.5 * fps)) {
        return bad("one-euro min_cutoff_hz must be in (0, fps/2)");
      }
      if (!(beta >= 0 && std::isfinite(beta))) return bad("one-euro beta must be >= 0");
      if (!(d_cutoff_hz > 0 && d_cutoff_hz < 0.5 * fps)) {
        return bad("one-euro d_cutoff_hz must be in (0, fps/2)");
      }
      break;
  }
  return Status::Ok();
}

StatusOr<TemporalFilterOptions> ParseFilterSpec(const std::string& spec) {
  std::vector<std::string> parts;
  std::stringstream ss(spec);
  std::string item;
  while (std::getline(ss, item, ':')) parts.push_back(item);
  if (parts.empty()) return Status::Error("empty filter spec");
  TemporalFilterOptions o;
  auto number = [&](size_t i, double* out) -> Status {
    if (i >= parts.size()) return Status::Ok();
    try {
      size_t used = 0;
      const double v = std::stod(parts[i], &used);
      if (used != parts[i].size()) throw std::invalid_argument("trailing");
      *out = v;
    } catch (const std::exception&) {
      return Status::Error("filter spec '" + spec + "': '" + parts[i] + "' is not a number");
    }
    return Status::Ok();
  };
  auto integer = [&](size_t i, int* out) -> Status {
    double v = *out;
    ARCO_RETURN_IF_ERROR(number(i, &v));
    if (v != std::floor(v) || std::abs(v) > 1e6) {
      return Status::Error("filter spec '" + spec + "': '" + parts[i] + "' is not an integer");
    }
    *out = static_cast<int>(v);
    return Status::Ok();
  };
  size_t max_parts = 1;
  if (parts[0] == "none") {
    o.kind = FilterKind::kNone;
  } else if (parts[0] == "butterworth") {
    o.kind = FilterKind::kButterworth;
    ARCO_RETURN_IF_ERROR(number(1, &o.cutoff_hz));
    ARCO_RETURN_IF_ERROR(integer(2, &o.order));
    max_parts = 3;
  } else if (parts[0] == "savgol") {
    o.kind = FilterKind::kSavitzkyGolay;
    ARCO_RETURN_IF_ERROR(integer(1, &o.window));
    ARCO_RETURN_IF_ERROR(integer(2, &o.polyorder));
    max_parts = 3;
  } else if (parts[0] == "oneeuro") {
    o.kind = FilterKind::kOneEuro;
    ARCO_RETURN_IF_ERROR(number(1, &o.min_cutoff_hz));
    ARCO_RETURN_IF_ERROR(number(2, &o.beta));
    ARCO_RETURN_IF_ERROR(number(3, &o.d_cutoff_hz));
    max_parts = 4;
  } else {
    return Status::Error("unknown filter '" + parts[0] +
                         "' (expected none, butterworth, savgol or oneeuro)");
  }
  if (parts.size() > max_parts) return Status::Error("filter spec '" + spec + "': too many values");
  return o;
}

std::string FilterSpecToString(const TemporalFilterOptions& o) {
  std::ostringstream s;
  switch (o.kind) {
    case FilterKind::kNone:
      return "none";
    case FilterKind::kButterworth:
      s << "butterworth:" << o.cutoff_hz << ":" << o.order;
      break;
    case FilterKind::kSavitzkyGolay:
      s << "savgol:" << o.window << ":" << o.polyorder;
      break;
    case FilterKind::kOneEuro:
      s << "oneeuro:" << o.min_cutoff_hz << ":" << o.beta << ":" << o.d_cutoff_hz;
      break;
  }
  return s.str();
}

void FillShortGaps(int max_gap_frames, std::vector<double>* x) {
  const int n = static_cast<int>(x->size());
  int i = 0;
  while (i < n) {
    if (std::isfinite((*x)[i])) {
      ++i;
      continue;
    }
    int j = i;
    while (j < n && !std::isfinite((*x)[j])) ++j;
    // Gap [i, j): interior when both neighbours exist.
    if (i > 0 && j < n && j - i <= max_gap_frames) {
      const double a = (*x)[i - 1], b = (*x)[j];
      for (int k = i; k < j; ++k) {
        const double t = static_cast<double>(k - i + 1) / (j - i + 1);
        (*x)[k] = a + t * (b - a);
      }
    }
    i = j;
  }
}

void FilterTrajectory(const TemporalFilterOptions& options, double fps, std::vector<double>* x) {
  const Status status = options.Validate(fps);
  if (!status.ok()) throw std::invalid_argument(status.message());
  FillShortGaps(options.max_gap_frames, x);
  if (options.kind == FilterKind::kNone) return;
  const int n = static_cast<int>(x->size());
  int i = 0;
  while (i < n) {
    if (!std::isfinite((*x)[i])) {
      ++i;
      continue;
    }
    int j = i;
    while (j < n && std::isfinite((*x)[j])) ++j;
    double* seg = x->data() + i;
    const int len = j - i;
    switch (options.kind) {
      case FilterKind::kButterworth:
        ButterworthFiltFilt(options, fps, seg, len);
        break;
      case FilterKind::kSavitzkyGolay:
        SavitzkyGolay(options, seg, len);
        break;
      case FilterKind::kOneEuro:
        OneEuro(options, fps, seg, len);
        break;
      case FilterKind::kNone:
        break;
    }
    i = j;
  }
}

void FilterPoints(const TemporalFilterOptions& options,
                  double fps,
                  const std::vector<int>& point_indices,
                  NpyArray<double>* points3d) {
  if (points3d->shape.size() != 3 || points3d->shape[2] != 3) {
    throw std::invalid_argument("FilterPoints: points must have shape (frames, points, 3)");
  }
  const int64_t frames = points3d->shape[0], points = points3d->shape[1];
  std::vector<double> track(static_cast<size_t>(frames));
  for (int p : point_indices) {
    if (p < 0 || p >= points) throw std::invalid_argument("FilterPoints: point index out of range");
    for (int k = 0; k < 3; ++k) {
      for (int64_t f = 0; f < frames; ++f) track[f] = points3d->at(f, p, k);
      FilterTrajectory(options, fps, &track);
      for (int64_t f = 0; f < frames; ++f) points3d->at(f, p, k) = track[f];
    }
  }
}

}  // namespace arco
