#include "arco/refine/paper_decode.h"

#include <cmath>
#include <limits>

namespace arco::refine {
namespace {

double Cents(double f0_hz) { return 1200.0 * std::log2(f0_hz / 440.0); }

// Nearest fingertip (index .. little) to a point; ties to the lower finger.
int NearestFinger(const hand::HandPointsMm& points, const Eigen::Vector3d& p) {
  int best = 1;
  double best_d = std::numeric_limits<double>::infinity();
  for (int k = 1; k <= 4; ++k) {
    const double d = (points[hand::TipKeypoint(static_cast<hand::Finger>(k))] - p).norm();
    if (d < best_d) {
      best_d = d;
      best = k;
    }
  }
  return best;
}

}  // namespace

std::vector<FrameContact> DecodePaper(const DecodeContext& context,
                                      const PaperOptions& options,
                                      const PitchModelOptions& pitch_options) {
  const ContactOptions& contact_options = pitch_options.contact;
  const RefineInput& input = *context.input;
  const InstrumentModel& model = *input.instrument;
  const int n = context.num_frames();
  std::vector<FrameContact> out(static_cast<size_t>(n));
  // The binding: string and finger, the run's mean pitch and the previous frame's.
  int bound_string = 0, bound_finger = 0;
  double run_sum_cents = 0, prev_cents = 0;
  int run_frames = 0;
  auto unbind = [&] { bound_string = bound_finger = run_frames = 0; };

  for (int f = 0; f < n; ++f) {
    FrameContact& c = out[static_cast<size_t>(f)];
    c = AudioOnlyContact(context, f);
    const FrameAudioState audio = context.analysis->frame_state[static_cast<size_t>(f)];
    // The paper's voicing: the tracker's confidence alone (no hysteresis, no notes).
    const bool weak =
        context.input->pitch[static_cast<size_t>(f)].confidence < pitch_options.min_confidence;
    if (audio == FrameAudioState::kRest || audio == FrameAudioState::kLowConfidence || weak) {
      if (audio != FrameAudioState::kRest) {
        c.state = ContactState::kUncertain;
        c.reason = ContactReason::kLowConfidence;
        c.note = -1;
      }
      unbind();
      continue;
    }
    // The paper has no notes: every confident voiced frame is used as it is.
    c.state = ContactState::kUncertain;
    c.reason = ContactReason::kNone;
    const double cents = Cents(c.f0_hz);
    if (!context.has_strings[static_cast<size_t>(f)]) {
      c.reason = ContactReason::kNoInstrument;
      unbind();
      continue;
    }
    const FrameCandidates cands =
        CandidatesForPitch(model, context.strings(f), c.f0_hz, contact_options);
    if (!cands.open_strings.empty()) {
      c.state = ContactState::kOpenString;
      c.string = cands.open_strings.front();
      unbind();
      continue;
    }
    if (cands.stopped.empty()) {
      c.reason = ContactReason::kUnplayable;
      unbind();
      continue;
    }
    // Keep the binding through vibrato.
    if (bound_string > 0) {
      const double mean = run_sum_cents / run_frames;
      const bool near = std::abs(cents - prev_cents) <= options.binding_cents &&
                        std::abs(cents - mean) <= options.binding_cents;
      const Candidate* kept = nullptr;
      for (const Candidate& cand : cands.stopped) {
        if (cand.string == bound_string) kept = &cand;
      }
      if (near && kept != nullptr) {
        SetPressed(*kept, bound_finger, &c);
        run_sum_cents += cents;
        ++run_frames;
        prev_cents = cents;
        continue;
      }
      unbind();
    }
    const auto& points = context.vision_points[static_cast<size_t>(f)];
    if (!points) {
      c.reason = ContactReason::kNoHand;
      continue;
    }
    // The candidate nearest the wrist (ties: the higher string, listed first).
    const Eigen::Vector3d& wrist = (*points)[0];
    const Candidate* best = &cands.stopped.front();
    for (const Candidate& cand : cands.stopped) {
      if ((cand.point_in_world - wrist).norm() < (best->point_in_world - wrist).norm()) {
        best = &cand;
      }
    }
    bound_string = best->string;
    bound_finger = NearestFinger(*points, best->point_in_world);
    run_sum_cents = cents;
    run_frames = 1;
    prev_cents = cents;
    SetPressed(*best, bound_finger, &c);
  }
  // Distances of the fitted fingertip to the chosen contact.
  for (int f = 0; f < n; ++f) {
    FrameContact& c = out[static_cast<size_t>(f)];
    const auto& points = context.vision_points[static_cast<size_t>(f)];
    if (!c.pressed()) continue;
    if (!points) {
      c.reason = ContactReason::kNoHand;  // the binding held through a frame without a hand
      continue;
    }
    const int tip = hand::TipKeypoint(static_cast<hand::Finger>(c.finger));
    c.tip_distance_vision_mm = ((*points)[tip] - c.point_in_world_mm).norm();
  }
  return out;
}

}  // namespace arco::refine
