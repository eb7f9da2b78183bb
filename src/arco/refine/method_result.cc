#include "arco/refine/method_result.h"

#include <stdexcept>

#include "arco/hand/kinematics.h"
#include "arco/registry/keypoint_layout.h"

namespace arco::refine {
namespace {

using wholebody::kLeftHandFirst;
constexpr int kNumWholeBody = wholebody::kNumPoints;

void SetPoint(NpyArray<double>* a, int64_t f, int64_t p, const Eigen::Vector3d& v) {
  for (int c = 0; c < 3; ++c) a->at(f, p, c) = v[c];
}

}  // namespace

std::string SpdContactLayoutName(const InstrumentModel& model) {
  const bool violin_like =
      model.kind() == InstrumentKind::kViolin || model.kind() == InstrumentKind::kViola;
  return violin_like ? "spd_violin_contact" : "spd_cello_contact";
}

NpyArray<double> BuildSpdPoints(const SpdSources& sources,
                                const std::vector<std::optional<hand::HandPose>>& hands,
                                const std::vector<FrameContact>* contacts) {
  const NpyArray<double>& base = sources.base_points_mm;
  if (sources.instrument == nullptr || base.shape.size() != 3 || base.shape[2] != 3) {
    throw std::invalid_argument("BuildSpdPoints: base points must be (F, P, 3) with an instrument");
  }
  const int64_t frames = base.shape[0];
  const int64_t num_base = base.shape[1];
  const int num_strings = sources.instrument->num_strings();
  if (num_base < kNumWholeBody || static_cast<int64_t>(hands.size()) != frames ||
      static_cast<int64_t>(sources.strings_in_world_mm.size()) != frames ||
      (contacts != nullptr && static_cast<int64_t>(contacts->size()) != frames) ||
      num_strings != 4) {
    throw std::invalid_argument("BuildSpdPoints: frame counts or point counts disagree");
  }
  NpyArray<double> out;
  out.shape = {frames, num_base + 13, 3};
  out.data.assign(static_cast<size_t>(frames * (num_base + 13) * 3), kNaN);
  const Eigen::Vector3d nan = Eigen::Vector3d::Constant(kNaN);
  for (int64_t f = 0; f < frames; ++f) {
    for (int64_t p = 0; p < num_base; ++p) {
      for (int c = 0; c < 3; ++c) out.at(f, p, c) = base.at(f, p, c);
    }
    const auto& h = hands[static_cast<size_t>(f)];
    hand::HandPointsMm points;
    if (h) {
      points = hand::ForwardKinematics(sources.hand_model, *h);
      for (int k = 0; k < hand::kNumHandKeypoints; ++k)
        SetPoint(&out, f, kLeftHandFirst + k, points[k]);
    }
    const auto& strings = sources.strings_in_world_mm[static_cast<size_t>(f)];
    const int64_t extra = num_base;
    if (static_cast<int>(strings.size()) == num_strings) {
      for (int pos = 0; pos < num_strings; ++pos) {  // lowest string first
        const StringSegment& s = strings[static_cast<size_t>(num_strings - 1 - pos)];
        SetPoint(&out, f, extra + 2 * pos, s.nut);
        SetPoint(&out, f, extra + 2 * pos + 1, s.bridge);
      }
    }
    if (contacts == nullptr) continue;
    const FrameContact& c = (*contacts)[static_cast<size_t>(f)];
    if (!c.pressed()) continue;
    SetPoint(&out, f, extra + 8, c.point_in_world_mm);
    if (h && c.finger >= 1 && c.finger <= 4) {
      for (int j = 0; j < 4; ++j) {
        SetPoint(&out,
                 f,
                 extra + 9 + j,
                 points[hand::KeypointIndex(static_cast<hand::Finger>(c.finger), j)]);
      }
    } else {
      for (int j = 0; j < 4; ++j) SetPoint(&out, f, extra + 9 + j, nan);
    }
  }
  return out;
}

}  // namespace arco::refine
