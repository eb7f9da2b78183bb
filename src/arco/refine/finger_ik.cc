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

// arco's IK of one frame: options.joints of the playing finger, anchored at the fitted
// pose and at the previous frame's solution of the same run (`prev`, temporal smoothness).
FrameIk SolveArcoFrame(const DecodeContext& context,
                       const FrameContact& c,
                       int f,
                       const ArcoIkOptions& options,
                       const FrameIk* prev) {
  hand::FingerIkOptions ik;
  ik.joints = options.joints;
  ik.reference_weight_mm_per_rad = options.reference_weight_mm_per_rad;
  ik.exact_reach = options.exact_reach;
  ik.max_iterations = options.max_iterations;
  // Restart from the hand IK's grid only when the tip would otherwise end beyond
  // max_residual_mm (a local minimum on a limit), not for the regularised solve's small
  // residual.
  ik.reach_tolerance_mm = options.max_residual_mm;
  if (options.temporal_weight_mm_per_rad > 0 && prev != nullptr && prev->solved) {
    ik.previous_pose = prev->pose;
    ik.previous_weight_mm_per_rad = options.temporal_weight_mm_per_rad;
  }
  return Solve(context, c, f, ik);
}

// Takes an arco IK result for one frame: the refined pose when the tip is within
// max_residual_mm, the whole hand shifted when within max_hand_shift_mm, otherwise the
// contact is rejected (kOutOfReach) and `hand` left alone. True when taken.
bool ApplyArcoIk(const DecodeContext& context,
                 const ArcoIkOptions& options,
                 const FrameIk& s,
                 FrameContact* c,
                 std::optional<hand::HandPose>* hand_out) {
  hand::HandPose pose = s.pose;
  double distance = s.distance_mm;
  const hand::Finger finger = static_cast<hand::Finger>(c->finger);
  if (distance > options.max_residual_mm) {
    if (distance > options.max_hand_shift_mm) {
      c->tip_distance_refined_mm = distance;
      c->state = ContactState::kUncertain;  // lift test: unreachable within the limits
      c->reason = ContactReason::kOutOfReach;
      return false;
    }
    const Eigen::Vector3d tip = hand::FingertipInWorld(context.input->hand_model, pose, finger);
    pose.wrist_in_world_mm += c->point_in_world_mm - tip;  // the whole hand, rigidly
    distance =
        (hand::FingertipInWorld(context.input->hand_model, pose, finger) - c->point_in_world_mm)
            .norm();
    // A timing annotation (before_onset, note_boundary) says more than the shift.
    if (c->reason == ContactReason::kNone) c->reason = ContactReason::kHandShifted;
  }
  c->tip_distance_refined_mm = distance;
  *hand_out = pose;
  return true;
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
                                                       const PitchModelOptions& pitch_options,
                                                       int lead_frames,
                                                       std::vector<FrameContact>* contacts,
                                                       IkStats* stats,
                                                       int num_threads) {
  const int n = context.num_frames();
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
  std::vector<FrameIk> final_ik(static_cast<size_t>(n));
  ParallelFor(
      static_cast<int64_t>(runs.size()),
      num_threads,
      [&](int64_t r, int) {
        const auto [first, last] = runs[static_cast<size_t>(r)];
        for (int f = first; f <= last; ++f) {
          const FrameIk* prev = f > first ? &final_ik[static_cast<size_t>(f - 1)] : nullptr;
          final_ik[static_cast<size_t>(f)] =
              SolveArcoFrame(context, (*contacts)[static_cast<size_t>(f)], f, options, prev);
        }
      },
      1);

  std::vector<std::optional<hand::HandPose>> hands = VisionHands(context);
  for (int f = 0; f < n; ++f) {
    const FrameIk& s = final_ik[static_cast<size_t>(f)];
    if (!s.solved) continue;
    Accumulate(s, stats);
    ApplyArcoIk(
        context, options, s, &(*contacts)[static_cast<size_t>(f)], &hands[static_cast<size_t>(f)]);
  }

  // The sound lags the hand at note changes: a rejected frame just before the next note
  // starts gets the next note's contact when that finger can reach it.
  const InstrumentModel& model = *context.input->instrument;
  for (int f = 0; f < n; ++f) {
    FrameContact& c = (*contacts)[static_cast<size_t>(f)];
    if (c.reason != ContactReason::kOutOfReach || !context.has_strings[static_cast<size_t>(f)] ||
        !context.input->vision_hand[static_cast<size_t>(f)]) {
      continue;
    }
    const FrameContact* next = nullptr;
    for (int g = f + 1; g < n && g <= f + lead_frames; ++g) {
      const FrameContact& cg = (*contacts)[static_cast<size_t>(g)];
      if (cg.pressed() && cg.note != c.note) {
        next = &cg;
        break;
      }
    }
    if (next == nullptr) continue;
    Candidate cand;
    if (!ContactOnString(
            model, context.strings(f), next->string, next->f0_hz, pitch_options.contact, &cand)) {
      continue;
    }
    FrameContact alt = c;
    alt.note = next->note;
    SetPressed(cand, next->finger, &alt);
    const int tip = hand::TipKeypoint(static_cast<hand::Finger>(alt.finger));
    alt.tip_distance_vision_mm =
        ((*context.vision_points[static_cast<size_t>(f)])[tip] - cand.point_in_world).norm();
    const FrameIk s = SolveArcoFrame(context, alt, f, options, nullptr);
    if (!s.solved) continue;
    Accumulate(s, stats);
    std::optional<hand::HandPose> pose = hands[static_cast<size_t>(f)];
    if (!ApplyArcoIk(context, options, s, &alt, &pose)) continue;
    if (alt.reason == ContactReason::kNone) alt.reason = ContactReason::kBeforeOnset;
    c = alt;
    hands[static_cast<size_t>(f)] = pose;
  }
  return hands;
}

}  // namespace arco::refine
