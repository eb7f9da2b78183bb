#include "arco/refine/hand_frame_depth.h"

#include <algorithm>
#include <cmath>

#include "arco/registry/instruments.h"
#include "arco/util/number_range.h"
#include "arco/util/parallel.h"

namespace arco::refine {

Status HandFrameDepthOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(CheckInRange("tip_sigma_mm", tip_sigma_mm, AboveZero(100)));
  ARCO_RETURN_IF_ERROR(CheckInRange("frame_sigma_mm", frame_sigma_mm, kFrameSigmaRangeMm));
  return rays.Validate().WithContext("rays");
}

int PlaceHandsInTheirFrame(const DecodeContext& context,
                           const std::vector<FrameContact>& contacts,
                           const Eigen::Vector3d& centre,
                           const HandFrameDepthOptions& options,
                           int num_threads,
                           std::vector<std::optional<hand::HandPose>>* hands) {
  const RefineInput& input = *context.input;
  const InstrumentKind kind = input.instrument->kind();
  const int frames = context.num_frames();
  std::vector<uint8_t> moved(static_cast<size_t>(frames), 0);
  ParallelFor(
      frames,
      num_threads,
      [&](int64_t f, int) {
        const size_t i = static_cast<size_t>(f);
        const FrameContact& c = contacts[i];
        auto& hand = (*hands)[i];
        if (!hand || !c.pressed() || c.finger < 1 || c.finger > 4 || !context.has_strings[i] ||
            !context.vision_points[i] || !c.point_in_world_mm.allFinite())
          return;
        const StringSegment* string = nullptr;
        for (const StringSegment& s : context.strings(static_cast<int>(f))) {
          if (s.string == c.string) string = &s;
        }
        if (!string) return;
        const Eigen::Vector3d along = (string->nut - string->bridge).normalized();
        const double vibrating_mm = along.dot(c.point_in_world_mm - string->bridge);
        const hand::HandPointsMm points = hand::ForwardKinematics(input.hand_model, *hand);
        std::vector<hand::AxisTarget> targets;
        const int pressing = hand::TipKeypoint(static_cast<hand::Finger>(c.finger));
        const Eigen::Vector3d ray = (points[pressing] - centre).normalized();
        targets.push_back({pressing,
                           ray,
                           ray.dot(centre) + (c.point_in_world_mm - centre).norm(),
                           options.tip_sigma_mm});
        const double own = FingerOffsetSemitones(kind, c.finger);
        for (int j = 1; j <= 4; ++j) {
          if (j == c.finger) continue;
          const double semitones = FingerOffsetSemitones(kind, j) - own;
          targets.push_back(
              {hand::TipKeypoint(static_cast<hand::Finger>(j)),
               along,
               along.dot(string->bridge) + vibrating_mm * std::exp2(-semitones / 12.0),
               options.frame_sigma_mm});
        }
        const std::optional<hand::RayDepthResult> placed =
            hand::PlaceKeypointsAlongRays(input.hand_model, centre, *hand, targets, options.rays);
        if (!placed) return;
        hand = placed->pose;
        moved[i] = 1;
      },
      16);
  return static_cast<int>(std::count(moved.begin(), moved.end(), uint8_t{1}));
}

}  // namespace arco::refine
