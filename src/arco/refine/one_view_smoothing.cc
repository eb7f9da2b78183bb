#include "arco/refine/one_view_smoothing.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

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

// The played note of a pressed frame (header comment): string, finger and the note's
// equal-tempered pitch in semitones from the capture's A4 (its median f0); nullopt when
// not pressed.
using PlayedNote = std::tuple<int, int, long>;
std::optional<PlayedNote> PlayedNoteOf(const DecodeContext& context, const FrameContact& c) {
  if (!c.pressed() || c.finger < 1 || c.finger > 4 || c.note < 0) return std::nullopt;
  const auto& notes = context.analysis->notes;
  if (static_cast<size_t>(c.note) >= notes.size()) return std::nullopt;
  const double f0 = notes[static_cast<size_t>(c.note)].f0_hz;
  if (!(f0 > 0)) return std::nullopt;
  return PlayedNote{
      c.string, c.finger, std::lround(12.0 * std::log2(f0 / context.input->a4_hz))};
}

// Each keypoint's coordinates, one by one, the median over the frames `members` (each
// with keypoints).
hand::HandPointsMm MedianKeypoints(const std::vector<std::optional<hand::HandPointsMm>>& local,
                                   const std::vector<size_t>& members) {
  hand::HandPointsMm median;
  std::vector<double> values;
  for (int k = 0; k < hand::kNumHandKeypoints; ++k) {
    for (int a = 0; a < 3; ++a) {
      values.clear();
      for (size_t i : members) values.push_back((*local[i])[k](a));
      median[k](a) = Median(values);
    }
  }
  return median;
}

}  // namespace

int SmoothHandsInInstrumentFrame(const DecodeContext& context,
                                 const std::vector<FrameContact>& contacts,
                                 int window_frames,
                                 double same_note_weight,
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
  // Each played note's keypoints: the median over its pressed frames (header comment).
  std::map<PlayedNote, std::vector<size_t>> frames_of_note;
  std::vector<std::optional<PlayedNote>> note_of_frame(static_cast<size_t>(n));
  if (same_note_weight > 0) {
    for (int f = 0; f < n; ++f) {
      const size_t i = static_cast<size_t>(f);
      if (!local[i]) continue;
      note_of_frame[i] = PlayedNoteOf(context, contacts[i]);
      if (note_of_frame[i]) frames_of_note[*note_of_frame[i]].push_back(i);
    }
  }
  std::map<PlayedNote, hand::HandPointsMm> note_median;
  for (const auto& [note, members] : frames_of_note) {
    if (static_cast<int>(members.size()) >= kMinSameNoteFrames)
      note_median[note] = MedianKeypoints(local, members);
  }
  const std::vector<std::optional<hand::HandPose>> refined = *hands;
  std::vector<uint8_t> changed(static_cast<size_t>(n), 0);
  ParallelFor(
      n,
      num_threads,
      [&](int64_t f, int) {
        const size_t i = static_cast<size_t>(f);
        if (!local[i]) return;
        const hand::HandPointsMm* same_note = nullptr;
        if (note_of_frame[i]) {
          const auto it = note_median.find(*note_of_frame[i]);
          if (it != note_median.end()) same_note = &it->second;
        }
        std::vector<size_t> around;
        for (int64_t g = std::max<int64_t>(0, f - window_frames);
             g <= std::min<int64_t>(n - 1, f + window_frames);
             ++g) {
          if (local[static_cast<size_t>(g)]) around.push_back(static_cast<size_t>(g));
        }
        hand::HandPointsMm held = MedianKeypoints(local, around);
        for (int k = 0; k < hand::kNumHandKeypoints; ++k) {
          if (same_note)
            held[k] = (1 - same_note_weight) * held[k] + same_note_weight * (*same_note)[k];
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
