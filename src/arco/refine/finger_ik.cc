#include "arco/refine/finger_ik.h"

#include <cmath>

#include "arco/hand/kinematics.h"
#include "arco/util/parallel.h"

namespace arco::refine {
namespace {

struct FrameIk {
  bool solved = false;
  hand::HandPose pose;
  double distance_mm = 0;
  int iterations = 0;
  int solves = 0;
  bool converged = false;
};

bool NeedsIk(const DecodeContext& context, const FrameContact& c, int f) {
  return c.pressed() && context.input->vision_hand[static_cast<size_t>(f)].has_value() &&
         c.point_in_world_mm.allFinite();
}

FrameIk Solve(const DecodeContext& context,
              const FrameContact& c,
              int f,
              const hand::FingerIkOptions& options) {
  const hand::FingerIkResult r =
      hand::SolveFingertipIk(context.input->hand_model,
                             *context.input->vision_hand[static_cast<size_t>(f)],
                             static_cast<hand::Finger>(c.finger),
                             c.point_in_world_mm,
                             options);
  FrameIk out;
  out.solved = r.status.ok();
  out.pose = r.pose;
  out.distance_mm = r.final_distance_mm;
  out.iterations = r.iterations;
  out.solves = r.solves;
  out.converged = r.converged;
  return out;
}

void Accumulate(const FrameIk& ik, IkStats* stats) {
  stats->solves += ik.solves;
  stats->iterations += ik.iterations;
  if (!ik.converged) ++stats->not_converged;
}

std::vector<std::optional<hand::HandPose>> VisionHands(const DecodeContext& context) {
  return context.input->vision_hand;
}

}  // namespace

std::vector<std::optional<hand::HandPose>> SolvePaperIk(const DecodeContext& context,
                                                        const PaperOptions& options,
                                                        std::vector<FrameContact>* contacts,
                                                        IkStats* stats,
                                                        int num_threads) {
  const int n = context.num_frames();
  hand::FingerIkOptions ik;
  ik.joints = hand::FingerIkJoints::kPipDip;
  ik.reference_weight_mm_per_rad = options.reference_weight_mm_per_rad;
  ik.exact_reach = true;
  ik.restarts = 0;  // a local solve from the fitted pose, as the paper's L-BFGS-B
  ik.max_iterations = options.max_iterations;
  std::vector<FrameIk> solved(static_cast<size_t>(n));
  ParallelFor(n, num_threads, [&](int64_t f, int) {
    const FrameContact& c = (*contacts)[static_cast<size_t>(f)];
    if (NeedsIk(context, c, static_cast<int>(f))) {
      solved[static_cast<size_t>(f)] = Solve(context, c, static_cast<int>(f), ik);
    }
  });
  std::vector<std::optional<hand::HandPose>> hands = VisionHands(context);
  for (int f = 0; f < n; ++f) {
    const FrameIk& s = solved[static_cast<size_t>(f)];
    if (!s.solved) continue;
    hands[static_cast<size_t>(f)] = s.pose;
    (*contacts)[static_cast<size_t>(f)].tip_distance_refined_mm = s.distance_mm;
    Accumulate(s, stats);
  }
  return hands;
}

std::vector<std::optional<hand::HandPose>> SolveArcoIk(const DecodeContext& context,
                                                       const ArcoIkOptions& options,
                                                       std::vector<FrameContact>* contacts,
                                                       IkStats* stats,
                                                       int num_threads) {
  const int n = context.num_frames();
  hand::FingerIkOptions ik;
  ik.joints = options.joints;
  ik.reference_weight_mm_per_rad = options.reference_weight_mm_per_rad;
  ik.exact_reach = true;
  ik.max_iterations = options.max_iterations;

  // Pass 1: each frame on its own.
  std::vector<FrameIk> pass1(static_cast<size_t>(n));
  ParallelFor(n, num_threads, [&](int64_t f, int) {
    const FrameContact& c = (*contacts)[static_cast<size_t>(f)];
    if (NeedsIk(context, c, static_cast<int>(f))) {
      pass1[static_cast<size_t>(f)] = Solve(context, c, static_cast<int>(f), ik);
    }
  });
  std::vector<FrameIk> final_ik = pass1;

  // Pass 2: a prior toward the pass-1 angles smoothed within runs of the same note, string
  // and finger.
  if (options.temporal_weight_mm_per_rad > 0 && options.temporal_sigma_frames > 0) {
    const int radius = static_cast<int>(std::ceil(3.0 * options.temporal_sigma_frames));
    auto same_run = [&](int a, int b) {
      const FrameContact& ca = (*contacts)[static_cast<size_t>(a)];
      const FrameContact& cb = (*contacts)[static_cast<size_t>(b)];
      return pass1[static_cast<size_t>(b)].solved && ca.note == cb.note && ca.string == cb.string &&
             ca.finger == cb.finger;
    };
    ParallelFor(n, num_threads, [&](int64_t f64, int) {
      const int f = static_cast<int>(f64);
      const FrameIk& own = pass1[static_cast<size_t>(f)];
      if (!own.solved) return;
      const FrameContact& c = (*contacts)[static_cast<size_t>(f)];
      const int finger = c.finger;
      double sum[4] = {0, 0, 0, 0}, weight = 0;
      // Walk out from f while the run continues (the run is contiguous).
      for (int dir = -1; dir <= 1; dir += 2) {
        for (int d = (dir < 0 ? 0 : 1); d <= radius; ++d) {
          const int g = f + dir * d;
          if (g < 0 || g >= n || !same_run(f, g)) break;
          const double w = std::exp(
              -0.5 * d * d / (options.temporal_sigma_frames * options.temporal_sigma_frames));
          for (int s = 0; s < 4; ++s) {
            sum[s] += w * pass1[static_cast<size_t>(g)].pose.angles_rad[4 * finger + s];
          }
          weight += w;
        }
      }
      hand::FingerIkOptions ik2 = ik;
      hand::HandPose smooth = own.pose;
      for (int s = 0; s < 4; ++s) smooth.angles_rad[4 * finger + s] = sum[s] / weight;
      ik2.previous_pose = smooth;
      ik2.previous_weight_mm_per_rad = options.temporal_weight_mm_per_rad;
      FrameIk second = Solve(context, c, f, ik2);
      second.solves += own.solves;
      second.iterations += own.iterations;
      final_ik[static_cast<size_t>(f)] = second;
    });
  }

  std::vector<std::optional<hand::HandPose>> hands = VisionHands(context);
  for (int f = 0; f < n; ++f) {
    const FrameIk& s = final_ik[static_cast<size_t>(f)];
    if (!s.solved) continue;
    Accumulate(s, stats);
    FrameContact& c = (*contacts)[static_cast<size_t>(f)];
    c.tip_distance_refined_mm = s.distance_mm;
    if (s.distance_mm > options.max_residual_mm) {
      c.state = ContactState::kUncertain;  // lift test: unreachable within the limits
      c.reason = ContactReason::kOutOfReach;
      continue;
    }
    hands[static_cast<size_t>(f)] = s.pose;
  }
  return hands;
}

}  // namespace arco::refine
