#include "arco/hand/hand_params.h"

#include <gtest/gtest.h>

#include "arco/hand/kinematics.h"

namespace arco::hand {
namespace {

TEST(HandParams, RoundTrip) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::vector<std::optional<HandPose>> hands(4);
  for (int f = 0; f < 4; ++f) {
    HandPose p;
    p.SetWristAngleAxis(Eigen::Vector3d(0.3, -0.2 * f, 0.1));
    p.world_from_wrist.translation = Eigen::Vector3d(10.0 * f, -5, 250);
    for (int d = 0; d < kNumJointDofs; ++d)
      p.angles_rad[static_cast<size_t>(d)] = 0.01 * d + 0.1 * f;
    hands[static_cast<size_t>(f)] = p;
  }
  hands[2].reset();
  const auto back = HandsFromParams(HandParams(hands), "x");
  ASSERT_TRUE(back.ok());
  ASSERT_EQ(back->size(), 4u);
  EXPECT_FALSE((*back)[2].has_value());
  const auto p0 = ForwardKinematics(model, *hands[0]);
  const auto q0 = ForwardKinematics(model, *(*back)[0]);
  for (int k = 0; k < 21; ++k) EXPECT_LT((p0[k] - q0[k]).norm(), 1e-9);
  NpyArray<double> bad;
  bad.shape = {3, 25};
  bad.data.assign(75, 0.0);
  EXPECT_FALSE(HandsFromParams(bad, "bad.npy").ok());
}

}  // namespace
}  // namespace arco::hand
