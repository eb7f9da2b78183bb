#include "arco/refine/decode_context.h"

#include "arco/util/parallel.h"

namespace arco::refine {

DecodeContext MakeDecodeContext(const RefineInput& input,
                                const PitchAnalysis& analysis,
                                int num_threads) {
  DecodeContext context;
  context.input = &input;
  context.analysis = &analysis;
  const int64_t n = static_cast<int64_t>(input.pitch.size());
  context.vision_points.assign(static_cast<size_t>(n), std::nullopt);
  context.has_strings.assign(static_cast<size_t>(n), 0);
  const int num_strings = input.instrument->num_strings();
  ParallelFor(n, num_threads, [&](int64_t f, int) {
    const size_t i = static_cast<size_t>(f);
    if (input.vision_hand[i]) {
      context.vision_points[i] = hand::ForwardKinematics(input.hand_model, *input.vision_hand[i]);
    }
    const std::vector<StringSegment>& strings = input.strings_in_world_mm[i];
    bool ok = static_cast<int>(strings.size()) == num_strings;
    for (const StringSegment& s : strings) {
      ok = ok && s.nut.allFinite() && s.bridge.allFinite() && (s.nut - s.bridge).norm() > 1e-6;
    }
    context.has_strings[i] = ok ? 1 : 0;
  });
  return context;
}

FrameContact AudioOnlyContact(const DecodeContext& context, int frame) {
  const size_t f = static_cast<size_t>(frame);
  const FramePitch& pitch = context.input->pitch[f];
  FrameContact out;
  out.f0_hz = std::isfinite(pitch.f0_hz) && pitch.f0_hz > 0 ? pitch.f0_hz : 0.0;
  out.confidence = std::isfinite(pitch.confidence) ? pitch.confidence : 0.0;
  out.note = context.analysis->note_of_frame[f];
  switch (context.analysis->frame_state[f]) {
    case FrameAudioState::kRest:
      out.state = ContactState::kRest;
      out.reason = ContactReason::kUnvoiced;
      break;
    case FrameAudioState::kLowConfidence:
      out.state = ContactState::kUncertain;
      out.reason = ContactReason::kLowConfidence;
      break;
    case FrameAudioState::kJumping:
    case FrameAudioState::kOutlier:
    case FrameAudioState::kUnstableNote:
      out.state = ContactState::kUncertain;
      out.reason = ContactReason::kUnstablePitch;
      break;
    case FrameAudioState::kShortNote:
      out.state = ContactState::kUncertain;
      out.reason = ContactReason::kShortNote;
      break;
    case FrameAudioState::kNote:
    case FrameAudioState::kBoundary:
      out.state = ContactState::kUncertain;
      out.reason = ContactReason::kNone;
      break;
  }
  return out;
}

void SetPressed(const Candidate& candidate, int finger, FrameContact* out) {
  out->state = ContactState::kPressed;
  out->reason = ContactReason::kNone;
  out->string = candidate.string;
  out->finger = finger;
  out->point_in_world_mm = candidate.point_in_world;
  out->from_nut_mm = candidate.from_nut_mm;
}

StringFrame StringFrameOf(const std::vector<StringSegment>& strings, int string) {
  StringFrame out;
  const StringSegment& s = strings[static_cast<size_t>(string - 1)];
  out.along = (s.nut - s.bridge).normalized();
  // Across the strings: from the highest to the lowest string, at the bridge and the nut.
  const Eigen::Vector3d across =
      (strings.back().bridge - strings.front().bridge) + (strings.back().nut - strings.front().nut);
  const Eigen::Vector3d normal = out.along.cross(across);
  if (normal.norm() > 1e-9) out.normal = normal.normalized();
  return out;
}

}  // namespace arco::refine
