#include "arco/refine/one_view_smoothing.h"

#include <Eigen/Geometry>
#include <algorithm>

#include "arco/hand/fit.h"
#include "arco/hand/ik.h"
#include "arco/util/parallel.h"
#include "arco/util/stats.h"

namespace arco::refine {
namespace {

// The instrument's frame of one frame's strings (header comment): rotation (columns x, y,
// z in the world) and origin.
struct Frame {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d origin;
};

std::optional<Frame> InstrumentFrame(const std::vector<StringSegment>& strings) {
  if (strings.size() < 2) return std::nullopt;
  Eigen::Vector3d nut = Eigen::Vector3d::Zero(), bridge = Eigen::Vector3d::Zero();
  for (const StringSegment& s : strings) {
    nut += s.nut;
    bridge += s.bridge;
  }
  nut /= static_cast<double>(strings.size());
  bridge /= static_cast<double>(strings.size());
  const Eigen::Vector3d x = (nut - bridge).normalized();
  const Eigen::Vector3d across =
      (strings.front().nut - strings.back().nut) + (strings.front().bridge - strings.back().bridge);
  const Eigen::Vector3d y = (across - across.dot(x) * x).normalized();
  Frame f;
  f.rotation.col(0) = x;
  f.rotation.col(1) = y;
  f.rotation.col(2) = x.cross(y);
  f.origin = bridge;
  if (!f.rotation.allFinite() || !f.origin.allFinite()) return std::nullopt;
  return f;
}

}  // namespace

int SmoothHandsInInstrumentFrame(const DecodeContext& context,
                                 const std::vector<FrameContact>& contacts,
                                 int window_frames,
                                 int num_threads,
                                 std::vector<std::optional<hand::HandPose>>* hands) {
  const RefineInput& input = *context.input;
  const hand::HandModel& model = input.hand_model;
  const int n = context.num_frames();
  // Each frame's keypoints in its instrument's frame.
  std::vector<std::optional<Frame>> frames(static_cast<size_t>(n));
  std::vector<std::optional<hand::HandPointsMm>> local(static_cast<size_t>(n));
  for (int f = 0; f < n; ++f) {
    const size_t i = static_cast<size_t>(f);
    if (!(*hands)[i] || !context.has_strings[i]) continue;
    frames[i] = InstrumentFrame(context.strings(f));
    if (!frames[i]) continue;
    hand::HandPointsMm p = hand::ForwardKinematics(model, *(*hands)[i]);
    for (auto& q : p) q = frames[i]->rotation.transpose() * (q - frames[i]->origin);
    local[i] = p;
  }
  const std::vector<std::optional<hand::HandPose>> refined = *hands;
  std::vector<uint8_t> changed(static_cast<size_t>(n), 0);
  ParallelFor(
      n,
      num_threads,
      [&](int64_t f, int) {
        const size_t i = static_cast<size_t>(f);
        if (!local[i]) return;
        hand::HandPointsMm held;
        std::vector<double> values;
        for (int k = 0; k < hand::kNumHandKeypoints; ++k) {
          for (int a = 0; a < 3; ++a) {
            values.clear();
            for (int64_t g = std::max<int64_t>(0, f - window_frames);
                 g <= std::min<int64_t>(n - 1, f + window_frames);
                 ++g) {
              const auto& p = local[static_cast<size_t>(g)];
              if (p) values.push_back((*p)[k](a));
            }
            held[k](a) = Median(values);
          }
          held[k] = frames[i]->rotation * held[k] + frames[i]->origin;
        }
        const hand::HandFit3dResult fit =
            hand::FitHandToPoints3d(model, held, hand::HandFit3dOptions{}, *refined[i]);
        if (!fit.ok) return;
        hand::HandPose s = fit.pose;
        // A pressed frame's playing fingertip stays where the refinement put it: the
        // finger bent there (its four angles), else the hand moved by what it misses.
        const FrameContact& c = contacts[i];
        if (c.pressed() && c.finger >= 1 && c.finger <= 4) {
          const auto finger = static_cast<hand::Finger>(c.finger);
          const Eigen::Vector3d tip = hand::FingertipInWorld(model, *refined[i], finger);
          hand::FingerIkOptions ik;
          ik.joints = hand::FingerIkJoints::kAll;
          const hand::FingerIkResult bent = hand::SolveFingertipIk(model, s, finger, tip, ik);
          if (bent.status.ok()) s = bent.pose;
          s.world_from_wrist.translation += tip - hand::FingertipInWorld(model, s, finger);
        }
        (*hands)[i] = s;
        changed[i] = 1;
      },
      4);
  return static_cast<int>(std::count(changed.begin(), changed.end(), uint8_t{1}));
}

}  // namespace arco::refine
