// Hands checked across views (hand_consistency.h) on a synthetic rig with known truth:
// two hands seen by 8 distorted cameras, one view's hand moved, swapped or one finger off.
#include "arco/capture/hand_consistency.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "arco/registry/keypoint_layout.h"
#include "arco/testing/synthetic_views.h"

namespace arco::capture {
namespace {

constexpr int kViews = 8;
constexpr double kPi = 3.14159265358979323846;

// A right-hand-sized hand (m) in hand_21 order, the wrist at `wrist`, fingers up (z).
std::array<Eigen::Vector3d, kHandPoints> MakeHand(const Eigen::Vector3d& wrist, double side) {
  std::array<Eigen::Vector3d, kHandPoints> p;
  p[0] = Eigen::Vector3d::Zero();
  const double thumb[4][3] = {
      {-0.03, -0.01, 0.03}, {-0.05, -0.02, 0.05}, {-0.065, -0.03, 0.07}, {-0.075, -0.035, 0.09}};
  for (int k = 0; k < 4; ++k)
    p[1 + k] = Eigen::Vector3d(side * thumb[k][0], thumb[k][1], thumb[k][2]);
  const double lengths[4] = {0.09, 0.04, 0.025, 0.02};  // wrist-MCP, then the phalanges
  for (int f = 0; f < 4; ++f) {
    Eigen::Vector3d q(side * (-0.025 + f * 0.017), 0, 0);
    for (int k = 0; k < 4; ++k) {
      q += Eigen::Vector3d(0, -0.008 * k, lengths[k] - 0.004 * f);
      p[5 + 4 * f + k] = q;
    }
  }
  for (auto& q : p) q += wrist;
  return p;
}

struct Scene {
  Rig rig;
  std::array<std::array<Eigen::Vector3d, kHandPoints>, 2> hands;  // left, right
  std::vector<float> rows;                                        // kViews x kNumPoints x 3
  int64_t stride = 3 * wholebody::kNumPoints;
  float* Hand(int v, int h) {
    return &rows[v * stride +
                 3 * (h == 0 ? wholebody::kLeftHandFirst : wholebody::kRightHandFirst)];
  }
};

Scene MakeScene(double noise_px = 0.5) {
  Scene s;
  testing::SyntheticRigOptions ro;
  ro.num_cameras = kViews;
  s.rig = testing::MakeSyntheticRig(ro);
  s.hands[0] = MakeHand(Eigen::Vector3d(0.3, 0.05, 0.95), -1);
  s.hands[1] = MakeHand(Eigen::Vector3d(-0.3, -0.05, 0.9), 1);
  s.rows.assign(static_cast<size_t>(kViews * s.stride), NAN);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0, noise_px);
  for (int v = 0; v < kViews; ++v) {
    for (int h = 0; h < 2; ++h) {
      float* hand = s.Hand(v, h);
      for (int i = 0; i < kHandPoints; ++i) {
        const auto px = s.rig.cameras[v].Project(s.hands[h][i]);
        EXPECT_TRUE(px.has_value());
        hand[3 * i] = static_cast<float>(px->x() + noise(rng));
        hand[3 * i + 1] = static_cast<float>(px->y() + noise(rng));
        hand[3 * i + 2] = 0.9f;
      }
    }
  }
  return s;
}

// Bit for bit (NaN equal to NaN).
bool Same(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

FrameHandCheck Check(const HandConsistencyOptions& o, Scene& s) {
  const Triangulator triangulator(s.rig, ConsensusTriangulationOptions(o));
  return CheckFrameHands(o, triangulator, s.rows.data(), kViews, s.stride);
}

int CountScoresBelow(Scene& s, float below) {
  int n = 0;
  for (int v = 0; v < kViews; ++v)
    for (int h = 0; h < 2; ++h)
      for (int i = 0; i < kHandPoints; ++i) n += s.Hand(v, h)[3 * i + 2] < below ? 1 : 0;
  return n;
}

TEST(CheckFrameHands, AgreeingViewsChangeNothingAndTheConsensusIsTheTruth) {
  Scene s = MakeScene();
  const std::vector<float> before = s.rows;
  const FrameHandCheck c = Check(HandConsistencyOptions(), s);
  EXPECT_TRUE(Same(s.rows, before));
  EXPECT_EQ(c.points_down_weighted, 0);
  for (int h = 0; h < 2; ++h) {
    EXPECT_EQ(c.consensus[h].num_valid, kHandPoints);
    for (int i = 0; i < kHandPoints; ++i) {
      EXPECT_LT((c.consensus[h].point_in_world[i] - s.hands[h][i]).norm(), 0.002) << h << " " << i;
    }
  }
  for (int v = 0; v < kViews; ++v) {
    EXPECT_FALSE(c.swapped[v]);
    for (int h = 0; h < 2; ++h) {
      EXPECT_TRUE(c.views[v][h].judged);
      EXPECT_FALSE(c.views[v][h].disagrees) << v << " " << h << " " << c.views[v][h].error_px;
      EXPECT_LT(c.views[v][h].error_px, 1.5);
      EXPECT_GT(c.views[v][h].size_px, 80);  // about 0.2 m at 3 m with f = 2260 px
    }
  }
}

TEST(CheckFrameHands, AMovedHandDisagreesAndGetsACropAroundTheConsensus) {
  Scene s = MakeScene();
  const int bad = 3;
  float* hand = s.Hand(bad, 1);
  for (int i = 0; i < kHandPoints; ++i) {  // 40 px to the right, 25 px down
    hand[3 * i] += 40;
    hand[3 * i + 1] += 25;
  }
  const std::vector<float> before = s.rows;
  const FrameHandCheck c = Check(HandConsistencyOptions(), s);
  EXPECT_TRUE(Same(s.rows, before));  // listed, not changed: the caller re-runs or down-weights
  for (int v = 0; v < kViews; ++v) {
    for (int h = 0; h < 2; ++h) {
      EXPECT_EQ(c.views[v][h].disagrees, v == bad && h == 1) << v << " " << h;
      EXPECT_EQ(c.views[v][h].recrop.has_value(), v == bad && h == 1);
    }
  }
  EXPECT_NEAR(c.views[bad][1].error_px, std::hypot(40, 25), 2);
  // The crop: centred near the true hand's box, turned so the fingers point up, about
  // twice the hand's extent.
  const detect::Roi& roi = *c.views[bad][1].recrop;
  Eigen::Vector2d lo(INFINITY, INFINITY), hi(-INFINITY, -INFINITY);
  for (const auto& q : s.hands[1]) {
    const Eigen::Vector2d p = *s.rig.cameras[bad].Project(q);
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector2d centre = 0.5 * (lo + hi);
  EXPECT_LT((Eigen::Vector2d(roi.centre.x, roi.centre.y) - centre).norm(), 0.2 * roi.side_px);
  EXPECT_GT(roi.side_px, 1.5 * (hi - lo).maxCoeff());
  EXPECT_LT(roi.side_px, 3.0 * (hi - lo).maxCoeff());
  EXPECT_LT(std::abs(roi.rotation_rad), 0.5);  // the hand is upright in every camera
  // The caller's verdicts: the moved hand back in place agrees, as it is it does not.
  const Camera& cam = s.rig.cameras[bad];
  EXPECT_GT(HandErrorPx(HandConsistencyOptions(), c.consensus[1], cam, hand), 40);
  HandConsistencyOptions o;
  EXPECT_EQ(DownWeightHand(o, hand), kHandPoints);
  for (int i = 0; i < kHandPoints; ++i) EXPECT_FLOAT_EQ(hand[3 * i + 2], o.low_score);
  EXPECT_EQ(DownWeightHand(o, hand), 0);  // already low
}

TEST(CheckFrameHands, SwappedHandsAreSwappedBack) {
  Scene s = MakeScene();
  const int bad = 5;
  const std::vector<float> truth = s.rows;
  std::swap_ranges(s.Hand(bad, 0), s.Hand(bad, 0) + 3 * kHandPoints, s.Hand(bad, 1));
  const FrameHandCheck c = Check(HandConsistencyOptions(), s);
  for (int v = 0; v < kViews; ++v) EXPECT_EQ(c.swapped[v], v == bad ? 1 : 0) << v;
  EXPECT_TRUE(Same(s.rows, truth));
  for (int v = 0; v < kViews; ++v)
    for (int h = 0; h < 2; ++h) EXPECT_FALSE(c.views[v][h].disagrees) << v << " " << h;
  EXPECT_EQ(c.points_down_weighted, 0);
}

TEST(CheckFrameHands, AViewWithOnlyOneHandOnTheWrongSideIsSwapped) {
  Scene s = MakeScene();
  const int bad = 2;
  // The view found only the right hand and called it the left.
  std::copy(s.Hand(bad, 1), s.Hand(bad, 1) + 3 * kHandPoints, s.Hand(bad, 0));
  std::fill(s.Hand(bad, 1), s.Hand(bad, 1) + 3 * kHandPoints, NAN);
  const FrameHandCheck c = Check(HandConsistencyOptions(), s);
  EXPECT_EQ(c.swapped[bad], 1);
  EXPECT_TRUE(std::isnan(s.Hand(bad, 0)[0]));
  EXPECT_TRUE(std::isfinite(s.Hand(bad, 1)[0]));
  EXPECT_FALSE(c.views[bad][1].disagrees);
}

TEST(CheckFrameHands, OneFingertipOffIsDownWeightedAlone) {
  Scene s = MakeScene();
  const int bad = 6, tip = 8;  // the left index fingertip
  s.Hand(bad, 0)[3 * tip] += 60;
  const FrameHandCheck c = Check(HandConsistencyOptions(), s);
  EXPECT_FALSE(c.views[bad][0].disagrees);
  EXPECT_EQ(c.points_down_weighted, 1);
  EXPECT_FLOAT_EQ(s.Hand(bad, 0)[3 * tip + 2], HandConsistencyOptions().low_score);
  EXPECT_EQ(CountScoresBelow(s, 0.3f), 1);
}

TEST(CheckFrameHands, TwoViewsAreNotEnoughToJudge) {
  Scene s = MakeScene();
  for (int v = 2; v < kViews; ++v)
    for (int h = 0; h < 2; ++h) std::fill(s.Hand(v, h), s.Hand(v, h) + 3 * kHandPoints, NAN);
  s.Hand(0, 1)[0] += 50;
  const std::vector<float> before = s.rows;
  const FrameHandCheck c = Check(HandConsistencyOptions(), s);
  EXPECT_TRUE(Same(s.rows, before));
  for (int v = 0; v < kViews; ++v)
    for (int h = 0; h < 2; ++h) EXPECT_FALSE(c.views[v][h].judged);
}

TEST(CheckFrameHands, LowScoresTakeNoPart) {
  Scene s = MakeScene();
  const int bad = 1;
  for (int i = 0; i < kHandPoints; ++i) {
    s.Hand(bad, 1)[3 * i] += 80;
    s.Hand(bad, 1)[3 * i + 2] = 0.1f;  // below min_score: ignored, not judged
  }
  const FrameHandCheck c = Check(HandConsistencyOptions(), s);
  EXPECT_FALSE(c.views[bad][1].judged);
  EXPECT_FALSE(c.views[bad][1].disagrees);
}

TEST(CheckFrameHands, InvariantToCameraOrder) {
  Scene s = MakeScene();
  for (int i = 0; i < kHandPoints; ++i) s.Hand(3, 1)[3 * i] += 40;  // one hand off
  s.Hand(6, 0)[3 * 8] += 60;                                        // one fingertip off
  Scene r = s;                                                      // the cameras in reverse order
  std::reverse(r.rig.cameras.begin(), r.rig.cameras.end());
  for (int v = 0; v < kViews; ++v) {
    std::copy(
        &s.rows[v * s.stride], &s.rows[(v + 1) * s.stride], &r.rows[(kViews - 1 - v) * r.stride]);
  }
  const FrameHandCheck a = Check(HandConsistencyOptions(), s);
  const FrameHandCheck b = Check(HandConsistencyOptions(), r);
  EXPECT_EQ(a.points_down_weighted, b.points_down_weighted);
  for (int v = 0; v < kViews; ++v) {
    EXPECT_TRUE(
        std::equal(&s.rows[v * s.stride],
                   &s.rows[(v + 1) * s.stride],
                   &r.rows[(kViews - 1 - v) * r.stride],
                   [](float x, float y) { return x == y || (std::isnan(x) && std::isnan(y)); }));
    for (int h = 0; h < 2; ++h) {
      EXPECT_EQ(a.views[v][h].disagrees, b.views[kViews - 1 - v][h].disagrees);
      EXPECT_NEAR(a.views[v][h].error_px, b.views[kViews - 1 - v][h].error_px, 1e-6);
    }
  }
}

TEST(CheckFrameHands, RejectsARigOfAnotherSize) {
  Scene s = MakeScene();
  const HandConsistencyOptions o;
  const Triangulator triangulator(s.rig, ConsensusTriangulationOptions(o));
  EXPECT_THROW(CheckFrameHands(o, triangulator, s.rows.data(), kViews - 1, s.stride),
               std::invalid_argument);
  EXPECT_THROW(CheckFrameHands(o, triangulator, s.rows.data(), kViews, 10), std::invalid_argument);
  HandConsistencyOptions bad = o;
  bad.low_score = 0.9;
  EXPECT_THROW(CheckFrameHands(bad, triangulator, s.rows.data(), kViews, s.stride),
               std::invalid_argument);
}

TEST(HandRoiFromPoints, FollowsTheHandsTurn) {
  Scene s = MakeScene();
  std::array<Eigen::Vector2d, kHandPoints> px;
  std::array<bool, kHandPoints> valid;
  valid.fill(true);
  for (int i = 0; i < kHandPoints; ++i) {
    // A hand drawn in the image with its fingers pointing right (+x): turned 90 degrees.
    const Eigen::Vector3d& q = s.hands[1][i] - s.hands[1][0];
    px[i] = Eigen::Vector2d(500 + 1000 * q.z(), 400 + 1000 * q.x());
  }
  const auto roi = HandRoiFromPoints(px, valid);
  ASSERT_TRUE(roi.has_value());
  // Fingers right means the crop's "up" (its -y) is the image's +x: rotation +pi/2.
  EXPECT_NEAR(roi->rotation_rad, kPi / 2, 0.15);
  EXPECT_GT(roi->centre.x, 500);  // towards the fingers from the wrist
  valid[9] = false;               // no middle finger base: no crop
  EXPECT_FALSE(HandRoiFromPoints(px, valid).has_value());
}

TEST(HandConsistencyOptions, RejectsValuesOutsideTheirRanges) {
  EXPECT_TRUE(HandConsistencyOptions().Validate().ok());
  const auto bad = [](auto set) {
    HandConsistencyOptions o;
    set(o);
    return !o.Validate().ok();
  };
  EXPECT_TRUE(bad([](auto& o) { o.min_score = 1.5; }));
  EXPECT_TRUE(bad([](auto& o) { o.max_reprojection_px = 0; }));
  EXPECT_TRUE(bad([](auto& o) { o.min_views = 1; }));
  EXPECT_TRUE(bad([](auto& o) { o.max_error_px = -1; }));
  EXPECT_TRUE(bad([](auto& o) { o.max_error_hand_fraction = 3; }));
  EXPECT_TRUE(bad([](auto& o) { o.max_point_error_hand_fraction = NAN; }));
  EXPECT_TRUE(bad([](auto& o) { o.swap_max_error_ratio = 1.5; }));
  EXPECT_TRUE(bad([](auto& o) { o.low_score = 0.5; }));  // not below min_score
  HandConsistencyOptions o;
  o.low_score = 0.4;
  EXPECT_NE(o.Validate().message().find("low_score"), std::string::npos);
}

}  // namespace
}  // namespace arco::capture
