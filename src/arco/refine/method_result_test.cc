#include "arco/refine/method_result.h"

#include <gtest/gtest.h>

#include "arco/hand/kinematics.h"
#include "arco/refine/refine.h"
#include "arco/refine/test_scene.h"
#include "arco/registry/keypoint_layout.h"

namespace arco::refine {
namespace {

SpdSources SourcesFor(const testing::Scene& scene) {
  SpdSources s;
  s.instrument = scene.input.instrument;
  s.hand_model = scene.input.hand_model;
  const int64_t frames = static_cast<int64_t>(scene.input.pitch.size());
  const int64_t points = 133 + static_cast<int64_t>(scene.model->keypoint_names().size());
  s.base_points_mm.shape = {frames, points, 3};
  s.base_points_mm.data.assign(static_cast<size_t>(frames * points * 3), 0.0);
  for (size_t i = 0; i < s.base_points_mm.data.size(); ++i) s.base_points_mm.data[i] = 0.25 * i;
  s.strings_in_world_mm = scene.input.strings_in_world_mm;
  return s;
}

TEST(BuildSpdPoints, SpdLayoutWithStringsContactAndPlayingFinger) {
  for (InstrumentKind kind : {InstrumentKind::kCello, InstrumentKind::kViolin}) {
    const testing::Scene scene = testing::MakeScene(kind, {{0, 0, 0, 3}, {2, 3, 4, 10}});
    RefineOptions o;
    // The layout is tested, not the IK: without the PIP's pull (refine_test.cc says why this
    // scene's fitted PIP is off) the playing tip lands on its contact.
    o.ik.pip_weight = 0;
    const RefineResult r = Refine(scene.input, o);
    const SpdSources sources = SourcesFor(scene);
    const NpyArray<double> a = BuildSpdPoints(sources, r.hand, &r.contacts);
    const KeypointLayout* layout = FindKeypointLayout(SpdContactLayoutName(*scene.model));
    ASSERT_NE(layout, nullptr);
    ASSERT_EQ(a.shape, (std::vector<int64_t>{13, layout->size(), 3}));
    EXPECT_EQ(layout->size(), kind == InstrumentKind::kCello ? 155 : 153);
    const int extra = layout->Find("string4_top");
    ASSERT_EQ(extra, kind == InstrumentKind::kCello ? 142 : 140);
    auto at = [&](int f, int p) {
      return Eigen::Vector3d(a.at(f, p, 0), a.at(f, p, 1), a.at(f, p, 2));
    };
    // Body and instrument points come through; the left hand is the refined one.
    EXPECT_EQ(a.at(5, 0, 1), sources.base_points_mm.at(5, 0, 1));
    EXPECT_EQ(a.at(5, 135, 2), sources.base_points_mm.at(5, 135, 2));
    const hand::HandPointsMm fk = hand::ForwardKinematics(scene.input.hand_model, *r.hand[5]);
    EXPECT_EQ(at(5, 91 + 12), fk[12]);
    // Strings lowest first, (nut, bridge).
    const auto& strings = scene.input.strings_in_world_mm[5];
    EXPECT_EQ(at(5, extra), strings[3].nut);
    EXPECT_EQ(at(5, extra + 1), strings[3].bridge);
    EXPECT_EQ(at(5, extra + 7), strings[0].bridge);
    // Contact and the playing finger (3: ring) on pressed frames, NaN on rests.
    ASSERT_TRUE(r.contacts[5].pressed());
    EXPECT_EQ(at(5, extra + 8), r.contacts[5].point_in_world_mm);
    EXPECT_EQ(at(5, extra + 9), fk[hand::KeypointIndex(hand::Finger::kRing, 0)]);
    EXPECT_EQ(at(5, extra + 12), fk[hand::TipKeypoint(hand::Finger::kRing)]);
    EXPECT_LT((at(5, extra + 12) - at(5, extra + 8)).norm(), 1.0);
    EXPECT_TRUE(std::isnan(a.at(1, extra + 8, 0)));
    EXPECT_TRUE(std::isnan(a.at(1, extra + 12, 0)));
    // Vision: strings, no contact.
    const NpyArray<double> v = BuildSpdPoints(sources, scene.input.vision_hand, nullptr);
    EXPECT_TRUE(std::isnan(v.at(5, extra + 8, 0)));
    EXPECT_EQ(v.at(5, extra, 0), strings[3].nut.x());
  }
}

}  // namespace
}  // namespace arco::refine
