#include "arco/refine/finger_ik.h"

#include <algorithm>
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
                       const FrameIk* prev,
                       const hand::HandPose* start = nullptr) {
  hand::FingerIkOptions ik;
  ik.joints = options.joints;
  ik.reference_weight_mm_per_rad = options.reference_weight_mm_per_rad;
  ik.exact_reach = options.exact_reach;
  ik.max_iterations = options.max_iterations;
  // Restart from the hand IK's grid only when the tip would otherwise end beyond
  // max_residual_mm (a local minimum on a limit), not for the regularised solve's small
  // residual.
  ik.reach_tolerance_mm = options.max_residual_mm;
  if (options.pip_weight > 0) {
    const hand::Finger finger = static_cast<hand::Finger>(c.finger);
    const size_t pip = static_cast<size_t>(hand::KeypointIndex(finger, 1));
    const auto& fitted = context.vision_points[static_cast<size_t>(f)];
    if (fitted && (*fitted)[pip].allFinite()) {
      Eigen::Vector3d target = (*fitted)[pip];
      const auto& detected = context.input->detected_left_hand;
      if (!detected.empty() && detected[static_cast<size_t>(f)] &&
          (*detected[static_cast<size_t>(f)])[pip].allFinite()) {
        target = 0.5 * (target + (*detected[static_cast<size_t>(f)])[pip]);
      }
      ik.pip_target_in_world_mm = target;
      ik.pip_weight = options.pip_weight;
    }
  }
  // A transition frame's contact is where the string is stopped while the hand moves
  // (arco_decode.h, glides; the frame's own pitch was not trusted): the finger's DIP
  // keypoint is held toward what the cameras saw, as the PIP's, so the tip moves toward
  // that contact only as far as the DIP allows (ArcoIkOptions::transition_dip_weight).
  const bool transition =
      c.reason == ContactReason::kNoteBoundary || c.reason == ContactReason::kBeforeOnset;
  if (options.transition_dip_weight > 0 && transition) {
    const hand::Finger finger = static_cast<hand::Finger>(c.finger);
    const size_t dip = static_cast<size_t>(hand::KeypointIndex(finger, 2));
    const auto& fitted = context.vision_points[static_cast<size_t>(f)];
    if (fitted && (*fitted)[dip].allFinite()) {
      Eigen::Vector3d target = (*fitted)[dip];
      const auto& detected = context.input->detected_left_hand;
      if (!detected.empty() && detected[static_cast<size_t>(f)] &&
          (*detected[static_cast<size_t>(f)])[dip].allFinite()) {
        target = 0.5 * (target + (*detected[static_cast<size_t>(f)])[dip]);
      }
      ik.dip_target_in_world_mm = target;
      ik.dip_weight = options.transition_dip_weight;
    }
  }
  if (options.temporal_weight_mm_per_rad > 0 && prev != nullptr && prev->solved) {
    ik.previous_pose = prev->pose;
    ik.previous_weight_mm_per_rad = options.temporal_weight_mm_per_rad;
  }
  // The distal joints first: when PIP and DIP alone bring the tip within max_residual_mm,
  // the MCP (and with it the PIP keypoint, which the cameras see well) keeps its fitted
  // angles; only a tip they cannot bring there frees the MCP's flexion, and only one that
  // still stays farther frees its abduction too, up to options.joints.
  if (options.distal_first && ik.joints != hand::FingerIkJoints::kPipDip) {
    FrameIk best;
    int solves = 0, iterations = 0;
    for (hand::FingerIkJoints stage : {hand::FingerIkJoints::kPipDip,
                                       hand::FingerIkJoints::kMcpFlexPipDip,
                                       hand::FingerIkJoints::kAll}) {
      hand::FingerIkOptions staged = ik;
      staged.joints = stage;
      FrameIk s = Solve(context, c, f, staged, start);
      solves += s.solves;
      iterations += s.iterations;
      // A later stage replaces an earlier one only when it comes nearer.
      if (s.solved && (!best.solved || s.distance_mm < best.distance_mm)) best = s;
      if ((best.solved && best.distance_mm <= options.max_residual_mm) || stage == ik.joints) {
        break;
      }
    }
    best.solves = solves;
    best.iterations = iterations;
    return best;
  }
  return Solve(context, c, f, ik, start);
}

// The whole-hand move toward an unreachable contact on frame f (ArcoIkOptions::
// detected_hand_shift): the remaining offset r may only be taken where the cameras say
// the fitted hand is off. d = the detected palm's displacement from the fitted palm (the
// per-axis median over wrist, thumb CMC and four MCPs of triangulated minus fitted); the
// hand moves by the part of r along d, at most d itself:
//   shift = d * clamp(r . d / |d|^2, 0, 1).
// A fit that lags a fast shift (the triangulated palm already moved toward the contact)
// follows it; a hand the cameras and the fit agree on stays, whatever the finger cannot
// reach (a real hand is not arco's model). Without a detected hand: the whole offset
// (the fitted wrist is assumed wrong, the former rule).
Eigen::Vector3d HandShift(const DecodeContext& context,
                          const ArcoIkOptions& options,
                          int f,
                          const Eigen::Vector3d& r) {
  const auto& detected = context.input->detected_left_hand;
  if (!options.detected_hand_shift || detected.empty()) return r;
  const auto& seen = detected[static_cast<size_t>(f)];
  const auto& fitted = context.vision_points[static_cast<size_t>(f)];
  if (!seen || !fitted) return Eigen::Vector3d::Zero();
  std::vector<double> axis[3];
  for (int k : {0, 1, 5, 9, 13, 17}) {  // wrist, thumb CMC, index..little MCP
    const Eigen::Vector3d& a = (*seen)[static_cast<size_t>(k)];
    if (!a.allFinite()) continue;
    const Eigen::Vector3d d = a - (*fitted)[static_cast<size_t>(k)];
    for (int c = 0; c < 3; ++c) axis[c].push_back(d[c]);
  }
  if (axis[0].size() < 3) return Eigen::Vector3d::Zero();  // the palm is hardly seen
  Eigen::Vector3d d;
  for (int c = 0; c < 3; ++c) {
    std::vector<double>& v = axis[c];
    std::sort(v.begin(), v.end());
    d[c] = v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  }
  const double dd = d.squaredNorm();
  if (dd < 1e-12) return Eigen::Vector3d::Zero();
  return d * std::clamp(r.dot(d) / dd, 0.0, 1.0);
}

// Takes an arco IK result for one frame: the refined pose when the tip is within
// max_residual_mm, the whole hand shifted when within max_hand_shift_mm, otherwise the
// contact is rejected (kOutOfReach) and `hand` left alone. True when taken.
bool ApplyArcoIk(const DecodeContext& context,
                 const ArcoIkOptions& options,
                 const FrameIk& s,
                 int f,
                 FrameContact* c,
                 std::optional<hand::HandPose>* hand_out,
                 Eigen::Vector3d* shift_out = nullptr) {
  hand::HandPose pose = s.pose;
  double distance = s.distance_mm;
  const hand::Finger finger = static_cast<hand::Finger>(c->finger);
  if (distance > options.max_residual_mm) {
    if (distance > options.max_hand_shift_mm) {
      c->tip_distance_refined_mm = distance;
      c->reason = ContactReason::kOutOfReach;
      if (!options.keep_unreachable) {
        c->state = ContactState::kUncertain;  // lift test: unreachable within the limits
        return false;
      }
      // The note is played whether or not arco's hand reaches it: the decision stands and
      // the hand stays where the cameras put it (a real hand is not arco's model). The
      // finger too, by default: a contact beyond what the model's finger and the allowed
      // hand move can explain says that the contact (a transition, a wrong note) or the
      // model is off, not the finger the cameras saw; stretched toward it, every joint of
      // the finger got worse on the real take (docs/accuracy.md). With
      // stretch_unreachable the finger goes as near as its joints allow (the former rule).
      if (options.stretch_unreachable) {
        *hand_out = pose;
      } else if (*hand_out) {
        c->tip_distance_refined_mm =
            (hand::FingertipInWorld(context.input->hand_model, **hand_out, finger) -
             c->point_in_world_mm)
                .norm();
      }
      return false;
    }
    const Eigen::Vector3d tip = hand::FingertipInWorld(context.input->hand_model, pose, finger);
    // The whole hand, rigidly, by its share of the offset: the contact is taken as
    // reachable by a hand where the cameras saw it. The output hand moves only with
    // move_hand (ArcoIkOptions).
    const Eigen::Vector3d shift = HandShift(context, options, f, c->point_in_world_mm - tip);
    if (shift_out != nullptr) *shift_out = shift;
    if (options.move_hand) {
      pose.world_from_wrist.translation += shift;
      distance =
          (hand::FingertipInWorld(context.input->hand_model, pose, finger) - c->point_in_world_mm)
              .norm();
    }
    // A timing annotation (before_onset, note_boundary) says more than the shift; a shift
    // below half a millimetre is none.
    if (c->reason == ContactReason::kNone && shift.norm() >= 0.5)
      c->reason = ContactReason::kHandShifted;
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
  // Each frame's whole-hand move of the first pass (zero where none was needed).
  std::vector<Eigen::Vector3d> shifts(static_cast<size_t>(n), Eigen::Vector3d::Zero());
  for (int f = 0; f < n; ++f) {
    const FrameIk& s = final_ik[static_cast<size_t>(f)];
    if (!s.solved) continue;
    Accumulate(s, stats);
    ApplyArcoIk(context,
                options,
                s,
                f,
                &(*contacts)[static_cast<size_t>(f)],
                &hands[static_cast<size_t>(f)],
                &shifts[static_cast<size_t>(f)]);
  }

  // The fitted hand lags fast shifts: a frame the lift test rejected inside a note whose
  // nearest accepted frames of the same note, string and finger (within
  // neighbour_shift_frames on either side) moved the whole hand starts from the fitted
  // hand moved by their mean shift, and is accepted when the rest is within
  // max_hand_shift_mm. A wrong decode has no accepted neighbours, so the lift test still
  // rejects it. Decided from the first pass only (independent of the frame order).
  if (options.neighbour_shift_frames > 0) {
    const std::vector<FrameContact> first_pass = *contacts;
    const std::vector<std::optional<hand::HandPose>> first_hands = hands;
    const int k = options.neighbour_shift_frames;
    std::vector<int> retried;
    for (int f = 0; f < n; ++f) {
      const FrameContact& c = first_pass[static_cast<size_t>(f)];
      if (c.reason == ContactReason::kOutOfReach && c.finger > 0 &&
          c.point_in_world_mm.allFinite() && context.input->vision_hand[static_cast<size_t>(f)]) {
        retried.push_back(f);
      }
    }
    std::vector<FrameIk> retry_ik(retried.size());
    std::vector<uint8_t> has_start(retried.size(), 0);
    ParallelFor(static_cast<int64_t>(retried.size()), num_threads, [&](int64_t r, int) {
      const int f = retried[static_cast<size_t>(r)];
      const FrameContact& c = first_pass[static_cast<size_t>(f)];
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      int count = 0;
      for (int side : {-1, 1}) {
        for (int d = 1; d <= k; ++d) {
          const int g = f + side * d;
          if (g < 0 || g >= n) break;
          const FrameContact& cg = first_pass[static_cast<size_t>(g)];
          if (cg.note != c.note || cg.string != c.string || cg.finger != c.finger) break;
          if (!cg.pressed() || !first_hands[static_cast<size_t>(g)] ||
              !context.input->vision_hand[static_cast<size_t>(g)]) {
            continue;
          }
          sum += shifts[static_cast<size_t>(g)];
          ++count;
          break;
        }
      }
      if (count == 0) return;
      hand::HandPose start = *context.input->vision_hand[static_cast<size_t>(f)];
      start.world_from_wrist.translation += sum / count;
      FrameContact alt = c;
      alt.state = ContactState::kPressed;
      retry_ik[static_cast<size_t>(r)] = SolveArcoFrame(context, alt, f, options, nullptr, &start);
      has_start[static_cast<size_t>(r)] = 1;
    });
    for (size_t r = 0; r < retried.size(); ++r) {
      if (!has_start[r] || !retry_ik[r].solved) continue;
      const int f = retried[r];
      Accumulate(retry_ik[r], stats);
      FrameContact alt = first_pass[static_cast<size_t>(f)];
      alt.state = ContactState::kPressed;
      alt.reason = ContactReason::kNone;
      std::optional<hand::HandPose> pose = hands[static_cast<size_t>(f)];
      if (!ApplyArcoIk(context, options, retry_ik[r], f, &alt, &pose)) continue;
      alt.reason = ContactReason::kHandShifted;  // moved with its neighbours
      if (!options.move_hand) {
        // Reachable with its neighbours' move; the hand stays where the cameras put it, with
        // the finger solved from there (the first pass's solution, or a new one for a frame
        // the decoder had already left unsolved).
        const FrameIk& first = final_ik[static_cast<size_t>(f)];
        const FrameIk from_fit =
            first.solved ? first : SolveArcoFrame(context, alt, f, options, nullptr);
        if (!from_fit.solved) continue;
        if (!first.solved) Accumulate(from_fit, stats);
        pose = from_fit.pose;
        alt.tip_distance_refined_mm = from_fit.distance_mm;
      }
      (*contacts)[static_cast<size_t>(f)] = alt;
      hands[static_cast<size_t>(f)] = pose;
    }
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
    if (!ApplyArcoIk(context, options, s, f, &alt, &pose)) continue;
    if (alt.reason == ContactReason::kNone) alt.reason = ContactReason::kBeforeOnset;
    c = alt;
    hands[static_cast<size_t>(f)] = pose;
  }

  return hands;
}

}  // namespace arco::refine
