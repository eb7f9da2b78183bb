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

// IK of the contact's finger, started from (and anchored at) `start`, by default the
// fitted (vision) hand.
FrameIk Solve(const DecodeContext& context,
              const FrameContact& c,
              int f,
              const hand::FingerIkOptions& options,
              const hand::HandPose* start = nullptr) {
  const hand::FingerIkResult r = hand::SolveFingertipIk(
      context.input->hand_model,
      start != nullptr ? *start : *context.input->vision_hand[static_cast<size_t>(f)],
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
  ik.exact_reach = false;  // one solve of the (nearly) unregularised reach cost
  ik.restarts = 0;         // a local solve from the fitted pose, as the paper's L-BFGS-B
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

  // Runs: maximal stretches of consecutive frames to correct with the same note, string and
  // finger. Within a run the frames are solved in time order, each with a prior toward the
  // previous frame's solution; runs are independent and solved in parallel.
  std::vector<std::pair<int, int>> runs;  // [first, last]
  for (int f = 0; f < n; ++f) {
    const FrameContact& c = (*contacts)[static_cast<size_t>(f)];
    if (!NeedsIk(context, c, f)) continue;
    if (!runs.empty() && runs.back().second == f - 1) {
      const FrameContact& p = (*contacts)[static_cast<size_t>(f - 1)];
      if (p.note == c.note && p.string == c.string && p.finger == c.finger) {
        runs.back().second = f;
        continue;
      }
    }
    runs.emplace_back(f, f);
  }
  const bool temporal = options.temporal_weight_mm_per_rad > 0;
  std::vector<FrameIk> final_ik(static_cast<size_t>(n));
  ParallelFor(
      static_cast<int64_t>(runs.size()),
      num_threads,
      [&](int64_t r, int) {
        const auto [first, last] = runs[static_cast<size_t>(r)];
        for (int f = first; f <= last; ++f) {
          const FrameContact& c = (*contacts)[static_cast<size_t>(f)];
          const FrameIk* prev = f > first ? &final_ik[static_cast<size_t>(f - 1)] : nullptr;
          if (!temporal || prev == nullptr || !prev->solved) {
            final_ik[static_cast<size_t>(f)] = Solve(context, c, f, ik);
            continue;
          }
          // The cost is symmetric in its two anchors, so the solve starts from the previous
          // frame's angles of this finger (near the answer: few iterations), anchored there
          // with the temporal weight, and the fitted pose is the second anchor.
          const hand::HandPose& vision = *context.input->vision_hand[static_cast<size_t>(f)];
          hand::HandPose start = vision;
          for (int s = 0; s < 4; ++s) {
            start.angles_rad[4 * c.finger + s] = prev->pose.angles_rad[4 * c.finger + s];
          }
          hand::FingerIkOptions chained = ik;
          chained.reference_weight_mm_per_rad = options.temporal_weight_mm_per_rad;
          chained.previous_pose = vision;
          chained.previous_weight_mm_per_rad = options.reference_weight_mm_per_rad;
          final_ik[static_cast<size_t>(f)] = Solve(context, c, f, chained, &start);
        }
      },
      1);

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
