#include "arco/synth/detections.h"

#include <algorithm>
#include <cmath>

#include "arco/synth/random.h"
#include "arco/util/parallel.h"

namespace arco::synth {
namespace {

constexpr double kPi = 3.14159265358979323846;

bool BodyOccludes(const DetectionFrame& f, const Eigen::Vector3d& cam, const Eigen::Vector3d& x) {
  const Eigen::Vector3d n = f.body_axis_x.cross(f.body_axis_y);
  const double denom = n.dot(x - cam);
  if (std::abs(denom) < 1e-9) return false;
  const double lambda = n.dot(f.body_centre - cam) / denom;
  const double len = (x - cam).norm();
  if (!(lambda > 0 && lambda < 1 - 5.0 / len)) return false;  // plane not crossed before x
  const Eigen::Vector3d h = cam + lambda * (x - cam) - f.body_centre;
  const double u = h.dot(f.body_axis_x) / f.body_half_x;
  const double v = h.dot(f.body_axis_y) / f.body_half_y;
  return u * u + v * v < 1;
}

double DistanceToSegment(const Eigen::Vector3d& p,
                         const Eigen::Vector3d& a,
                         const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

bool TorsoOccludes(const DetectionFrame& f, const Eigen::Vector3d& cam, const Eigen::Vector3d& x) {
  if (DistanceToSegment(x, f.torso_a, f.torso_b) < f.torso_radius) return false;  // on the torso
  const double len = (x - cam).norm();
  const double end = 1 - 30.0 / len;
  for (int i = 1; i <= 24; ++i) {
    const double t = end * i / 24.0;
    if (DistanceToSegment(cam + t * (x - cam), f.torso_a, f.torso_b) < f.torso_radius) return true;
  }
  return false;
}

}  // namespace

Status DetectionOptions::Validate() const {
  if (!(noise_px >= 0 && noise_px < 200)) return Status::Error("noise_px must be in [0, 200)");
  if (!(outlier_rate >= 0 && outlier_rate <= 1))
    return Status::Error("outlier_rate must be in [0, 1]");
  if (!(occlusion_rate >= 0 && occlusion_rate <= 1)) {
    return Status::Error("occlusion_rate must be in [0, 1]");
  }
  if (!(finger_bias_mm >= 0 && finger_bias_mm < 200)) {
    return Status::Error("finger_bias_mm must be in [0, 200)");
  }
  if (!(jitter_mm >= 0 && jitter_mm < 100) || !(jitter_time_s >= 0)) {
    return Status::Error("jitter_mm must be in [0, 100) and jitter_time_s >= 0");
  }
  if (!(instrument_noise_scale >= 0) || !(bow_noise_scale >= 0)) {
    return Status::Error("noise scales must be >= 0");
  }
  if (!(finger_offset_mm >= 0 && finger_offset_mm < 100) ||
      !(finger_offset_time_s >= 0 && finger_offset_time_s < 1e6)) {
    return Status::Error("finger_offset_mm must be in [0, 100) and finger_offset_time_s >= 0");
  }
  if (!(hand_back_max_deg >= 0 && hand_back_max_deg <= 90)) {
    return Status::Error("hand_back_max_deg must be in [0, 90]");
  }
  if (!(finger_confusion_rate >= 0 && finger_confusion_rate <= 1)) {
    return Status::Error("finger_confusion_rate must be in [0, 1]");
  }
  return Status::Ok();
}

NpyArray<float> EmulateDetections(const Rig& rig,
                                  const std::vector<DetectionFrame>& frames,
                                  const DetectionLayout& layout,
                                  const DetectionOptions& o,
                                  double fps,
                                  uint64_t seed,
                                  int num_threads) {
  const int num_frames = static_cast<int>(frames.size());
  const int num_views = static_cast<int>(rig.cameras.size());
  const int num_points = layout.num_points;
  NpyArray<float> out;
  out.shape = {num_frames, num_views, num_points, 3};
  out.data.assign(static_cast<size_t>(out.size()), std::nanf(""));
  std::vector<bool> is_bow(static_cast<size_t>(num_points), false);
  std::vector<bool> is_torso(static_cast<size_t>(num_points), false);
  for (int b : layout.bow_points) is_bow[static_cast<size_t>(b)] = true;
  for (int b : layout.torso_points) is_torso[static_cast<size_t>(b)] = true;

  // View-consistent 3D error, AR(1) in time per keypoint and axis.
  std::vector<Eigen::Vector3d> jitter(
      static_cast<size_t>(num_frames) * static_cast<size_t>(num_points), Eigen::Vector3d::Zero());
  if (o.jitter_mm > 0) {
    Rng rng = Rng::Stream(seed, 999);
    const double a = o.jitter_time_s > 0 ? std::exp(-1.0 / (fps * o.jitter_time_s)) : 0.0;
    const double b = std::sqrt(1 - a * a);
    for (int p = 0; p < num_points; ++p) {
      double scale = 1.5;  // body, feet, face
      if (p >= layout.left_hand_first && p < layout.right_hand_first + wholebody::kNumHandPoints)
        scale = 1.0;
      if (p >= layout.instrument_first) scale = is_bow[static_cast<size_t>(p)] ? 1.0 : 0.3;
      Eigen::Vector3d state(rng.Normal(), rng.Normal(), rng.Normal());
      for (int fr = 0; fr < num_frames; ++fr) {
        if (fr > 0)
          state = a * state + b * Eigen::Vector3d(rng.Normal(), rng.Normal(), rng.Normal());
        jitter[static_cast<size_t>(fr) * static_cast<size_t>(num_points) + static_cast<size_t>(p)] =
            o.jitter_mm * scale * state;
      }
    }
  }

  // 7. Per-finger offset of the left hand, AR(1) per finger and axis, shared by all views.
  // finger_offset[fr * 5 + finger] at the tip; joint j (0 = MCP .. 3 = tip) gets (j+1)/4.
  std::vector<Eigen::Vector3d> finger_offset;
  if (o.finger_offset_mm > 0) {
    finger_offset.assign(static_cast<size_t>(num_frames) * 5, Eigen::Vector3d::Zero());
    Rng rng = Rng::Stream(seed, 997);
    const double a =
        o.finger_offset_time_s > 0 ? std::exp(-1.0 / (fps * o.finger_offset_time_s)) : 0.0;
    const double b = std::sqrt(1 - a * a);
    for (int finger = 0; finger < 5; ++finger) {
      Eigen::Vector3d state(rng.Normal(), rng.Normal(), rng.Normal());
      for (int fr = 0; fr < num_frames; ++fr) {
        if (fr > 0)
          state = a * state + b * Eigen::Vector3d(rng.Normal(), rng.Normal(), rng.Normal());
        finger_offset[static_cast<size_t>(fr) * 5 + static_cast<size_t>(finger)] =
            o.finger_offset_mm * state;
      }
    }
  }
  // Left-hand keypoint k (1..20) -> finger 0..4 and joint 0..3; the wrist is -1.
  auto left_finger_joint = [&](int p, int* finger, int* joint) {
    const int k = p - layout.left_hand_first;
    if (k < 1 || k >= wholebody::kNumHandPoints) return false;
    *finger = (k - 1) / 4;
    *joint = (k - 1) % 4;
    return true;
  };
  const double back_cos = std::cos(o.hand_back_max_deg * kPi / 180.0);

  ParallelFor(num_views, num_threads, [&](int64_t view, int) {
    const Camera& cam = rig.cameras[static_cast<size_t>(view)];
    const Eigen::Vector3d centre = cam.CenterInWorld();
    Rng rng = Rng::Stream(seed, 1000 + static_cast<uint64_t>(view));
    Rng confusion_rng = Rng::Stream(seed, 5000 + static_cast<uint64_t>(view));
    for (int fr = 0; fr < num_frames; ++fr) {
      const DetectionFrame& f = frames[static_cast<size_t>(fr)];
      auto slot = [&](int p) {
        return &out.data[((static_cast<size_t>(fr) * num_views + static_cast<size_t>(view)) *
                              num_points +
                          static_cast<size_t>(p)) *
                         3];
      };
      for (int p = 0; p < num_points; ++p) {
        // Draw every random number for every point so one point's fate does not
        // shift the stream of the next.
        const double nx = rng.Normal(), ny = rng.Normal(), score_jitter = rng.Normal();
        const bool dropout = rng.Bernoulli(o.occlusion_rate);
        const bool outlier = rng.Bernoulli(o.outlier_rate);
        const double angle = rng.Uniform(0, 2 * kPi);
        const double far_px = rng.Uniform(40, 250), occl_px = rng.Uniform(0, 25);
        const double occl_score = rng.Uniform(0.05, 0.45), outlier_score = rng.Uniform(0.4, 0.9);
        Eigen::Vector3d x = f.points[static_cast<size_t>(p)];
        if (!x.allFinite()) continue;
        x += jitter[static_cast<size_t>(fr) * static_cast<size_t>(num_points) +
                    static_cast<size_t>(p)];
        if (p == f.bias_tip) x += o.finger_bias_mm * f.bias_direction;
        if (p == f.bias_dip) x += 0.5 * o.finger_bias_mm * f.bias_direction;
        int finger = -1, joint = -1;
        const bool left_finger_point = left_finger_joint(p, &finger, &joint);
        if (left_finger_point && !finger_offset.empty()) {
          x += (joint + 1) / 4.0 *
               finger_offset[static_cast<size_t>(fr) * 5 + static_cast<size_t>(finger)];
        }
        // 8. Seen from behind: the back of the hand faces the camera.
        const bool behind_hand = o.hand_back_max_deg > 0 && left_finger_point && joint >= 1 &&
                                 f.left_hand_back.squaredNorm() > 0.5 &&
                                 f.left_hand_back.dot((centre - x).normalized()) > back_cos;
        const auto pixel = cam.Project(x);
        if (!pixel || pixel->x() < -0.5 || pixel->y() < -0.5 || pixel->x() > cam.width - 0.5 ||
            pixel->y() > cam.height - 0.5) {
          float* s = slot(p);
          s[2] = 0.0f;  // x, y stay NaN: not in this view
          continue;
        }
        double scale = 1;
        if (p >= layout.instrument_first)
          scale = is_bow[static_cast<size_t>(p)] ? o.bow_noise_scale : o.instrument_noise_scale;
        const double sigma = o.noise_px * scale;
        Eigen::Vector2d err(nx * sigma, ny * sigma);
        double score;
        const bool occluded = o.geometric_occlusion &&
                              (BodyOccludes(f, centre, x) ||
                               (!is_torso[static_cast<size_t>(p)] && TorsoOccludes(f, centre, x)));
        if (outlier) {
          err = far_px * Eigen::Vector2d(std::cos(angle), std::sin(angle));
          score = outlier_score;
        } else if (occluded || dropout || behind_hand) {
          err = 4 * err + occl_px * Eigen::Vector2d(std::cos(angle), std::sin(angle));
          score = occl_score;
        } else {
          const double e = err.norm() / std::max(o.noise_px, 1e-9);
          score = std::clamp(0.98 - 0.06 * e + 0.02 * score_jitter, 0.5, 1.0);
        }
        float* s = slot(p);
        s[0] = static_cast<float>(pixel->x() + err.x());
        s[1] = static_cast<float>(pixel->y() + err.y());
        s[2] = static_cast<float>(score);
      }
      // 9. Neighbouring fingers of the left hand trade PIP, DIP and tip.
      if (o.finger_confusion_rate > 0) {
        const bool swap = confusion_rng.Bernoulli(o.finger_confusion_rate);
        const int pair = std::min(2, static_cast<int>(confusion_rng.Uniform(0, 3)));
        if (swap) {
          for (int j = 1; j < 4; ++j) {
            float* a = slot(layout.left_hand_first + 1 + 4 * (1 + pair) + j);
            float* b = slot(layout.left_hand_first + 1 + 4 * (2 + pair) + j);
            for (int c = 0; c < 3; ++c) std::swap(a[c], b[c]);
          }
        }
      }
      // Left/right hand swap for this view and frame.
      if (rng.Bernoulli(o.outlier_rate)) {
        for (int k = 0; k < wholebody::kNumHandPoints; ++k) {
          float* a = slot(layout.left_hand_first + k);
          float* b = slot(layout.right_hand_first + k);
          for (int c = 0; c < 3; ++c) std::swap(a[c], b[c]);
        }
      }
    }
  });
  return out;
}

}  // namespace arco::synth
