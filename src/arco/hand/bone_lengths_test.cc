#include "arco/hand/bone_lengths.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>

#include "arco/hand/hand_test_util.h"

namespace arco::hand {
namespace {

// A performer whose bones differ from the prior by up to +-15 %, observed over
// `num_frames` random poses with noise, gross outliers and missing keypoints.
struct Capture {
  HandModel truth = HandModel::Default(HandSide::kLeft);
  std::vector<HandPointsMm> frames;
};

Capture MakeCapture(int num_frames, double noise_mm, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n(0.0, 1.0);
  const HandModel prior = HandModel::Default(HandSide::kLeft);
  BoneLengthsMm lengths = prior.bone_lengths_mm();
  for (int k = 1; k < kNumHandKeypoints; ++k) lengths[k] *= 1.05 + 0.3 * (u(rng) - 0.5);
  Capture c;
  c.truth = prior.WithBoneLengths(lengths).value();
  for (int f = 0; f < num_frames; ++f) {
    HandPointsMm p = ForwardKinematics(c.truth, testing::RandomPose(c.truth, rng));
    for (auto& q : p) q += noise_mm * Eigen::Vector3d(n(rng), n(rng), n(rng));
    if (u(rng) < 0.15) p[static_cast<int>(u(rng) * 21)] += Eigen::Vector3d(0, 35, 0);  // outlier
    if (u(rng) < 0.2) p[static_cast<int>(u(rng) * 21)].setConstant(std::nan(""));      // missing
    c.frames.push_back(p);
  }
  return c;
}

TEST(EstimateBoneLengths, RecoversAPerformersBonesFromNoisyFrames) {
  std::mt19937 rng(12);
  const Capture c = MakeCapture(300, 2.0, rng);
  const HandModel prior = HandModel::Default(HandSide::kLeft);
  const StatusOr<BoneLengthEstimate> est =
      EstimateBoneLengths(c.frames, prior, BoneLengthOptions{});
  ASSERT_TRUE(est.ok()) << est.status().message();
  double worst = 0;
  for (int k = 1; k < kNumHandKeypoints; ++k) {
    EXPECT_TRUE(est->from_data[k]);
    EXPECT_FALSE(est->clamped[k]);
    EXPECT_NEAR(est->lengths_mm[k], c.truth.bone_length_mm(k), 1.0) << KeypointName(k);
    worst = std::max(worst, std::abs(est->lengths_mm[k] - c.truth.bone_length_mm(k)));
  }
  std::printf(
      "[ bones ] 300 frames, 2 mm noise, 15%% outlier and 20%% missing frames: worst bone "
      "error %.2f mm, hand scale %.3f\n",
      worst,
      est->hand_scale);
  const StatusOr<HandModel> performer = prior.WithBoneLengths(est->lengths_mm);
  ASSERT_TRUE(performer.ok());
}

// Noise lengthens short bones: with 4 mm per axis on every keypoint (the spread of a
// triangulated fingertip on a real take re-captured with 20 views, docs/hand.md) the
// median distance over-estimates a 25 mm phalanx by about tau^2 / L = 1.3 mm. The
// correction must remove that bias, not just shrink every bone.
TEST(EstimateBoneLengths, RemovesTheUpwardBiasOfNoisyDistances) {
  std::mt19937 rng(7);
  const Capture c = MakeCapture(800, 4.0, rng);
  const HandModel prior = HandModel::Default(HandSide::kLeft);
  auto signed_and_abs = [&](bool correct) {
    BoneLengthOptions options;
    options.correct_noise_bias = correct;
    const auto est = EstimateBoneLengths(c.frames, prior, options);
    EXPECT_TRUE(est.ok());
    double sum = 0, sum_abs = 0;
    int n = 0;
    for (int k = 1; k < kNumHandKeypoints; ++k) {
      if (ParentKeypoint(k) == 0) continue;  // the phalanges (the palm's bones are long)
      const double e = est->lengths_mm[k] - c.truth.bone_length_mm(k);
      sum += e;
      sum_abs += std::abs(e);
      ++n;
    }
    return std::make_pair(sum / n, sum_abs / n);
  };
  const auto plain = signed_and_abs(false);
  const auto corrected = signed_and_abs(true);
  std::printf(
      "[ bones ] 4 mm noise, phalanges: mean error %+.2f mm (abs %.2f) plain median, "
      "%+.2f mm (abs %.2f) corrected\n",
      plain.first,
      plain.second,
      corrected.first,
      corrected.second);
  EXPECT_GT(plain.first, 0.8);
  EXPECT_LT(std::abs(corrected.first), 0.4);
  EXPECT_LT(corrected.second, 0.6 * plain.second);
}

// One camera: the lifted hand lies at one depth per frame, so each distance is the bone's
// projection on a plane parallel to the image. A higher quantile of the projections comes
// nearer the bones than their median (HandStageOptions::one_view_bone_quantile).
TEST(EstimateBoneLengths, AHigherQuantileOfProjectedDistancesNearsTheBones) {
  std::mt19937 rng(5);
  Capture c = MakeCapture(300, 1.0, rng);
  for (HandPointsMm& p : c.frames)
    for (auto& q : p) q.z() = 0;  // every point onto one plane (the camera looks along z)
  const HandModel prior = HandModel::Default(HandSide::kLeft);
  const auto mean_error = [&](double quantile) {
    BoneLengthOptions o;
    o.quantile = quantile;
    const StatusOr<BoneLengthEstimate> est = EstimateBoneLengths(c.frames, prior, o);
    EXPECT_TRUE(est.ok()) << est.status().message();
    double sum = 0;
    for (int k = 1; k < kNumHandKeypoints; ++k)
      sum += std::abs(est->lengths_mm[k] - c.truth.bone_length_mm(k));
    return sum / (kNumHandKeypoints - 1);
  };
  const double median = mean_error(0.5), upper = mean_error(0.75);
  std::printf(
      "[ bones ] projections: mean bone error %.2f mm (median), %.2f mm (0.75)\n", median, upper);
  EXPECT_LT(upper, 0.7 * median);
  BoneLengthOptions bad;
  bad.quantile = 1.0;
  EXPECT_FALSE(bad.Validate().ok());
  bad.quantile = 0.4;
  EXPECT_FALSE(bad.Validate().ok());
}

// The palm's and the thumb's bones take their own quantiles (BoneLengthOptions::
// palm_quantile, thumb_quantile); every other bone keeps `quantile`.
TEST(EstimateBoneLengths, ThePalmAndTheThumbTakeTheirOwnQuantiles) {
  std::mt19937 rng(7);
  Capture c = MakeCapture(300, 1.0, rng);
  for (HandPointsMm& p : c.frames)
    for (auto& q : p) q.z() = 0;  // projections, as one camera's lift gives
  const HandModel prior = HandModel::Default(HandSide::kLeft);
  BoneLengthOptions same;
  same.quantile = 0.75;
  same.palm_quantile = 0.75;
  same.thumb_quantile = 0.75;
  BoneLengthOptions own = same;
  own.palm_quantile = 0.9;
  own.thumb_quantile = 0.6;
  const StatusOr<BoneLengthEstimate> a = EstimateBoneLengths(c.frames, prior, same);
  const StatusOr<BoneLengthEstimate> b = EstimateBoneLengths(c.frames, prior, own);
  ASSERT_TRUE(a.ok() && b.ok());
  for (int k = 1; k < kNumHandKeypoints; ++k) {
    const bool thumb = k <= KeypointIndex(Finger::kThumb, 3);
    const bool palm = !thumb && ParentKeypoint(k) == 0;
    if (thumb)
      EXPECT_LT(b->lengths_mm[k], a->lengths_mm[k]) << k;
    else if (palm)
      EXPECT_GT(b->lengths_mm[k], a->lengths_mm[k]) << k;
    else
      EXPECT_EQ(b->lengths_mm[k], a->lengths_mm[k]) << k;
  }
  BoneLengthOptions bad;
  bad.palm_quantile = 1.0;
  EXPECT_FALSE(bad.Validate().ok());
  bad = BoneLengthOptions{};
  bad.thumb_quantile = 0.4;
  EXPECT_FALSE(bad.Validate().ok());
}

TEST(EstimateBoneLengths, ThePalmAsOnePieceTakesOneScale) {
  // A performer's palm 12 % larger than the prior's, seen with each of its bones
  // foreshortened by its own factor (one view: the little finger's most, as the real
  // take's camera sees the cellist's palm turned away). Each bone by itself keeps its
  // factor's error; the palm as one piece takes one scale for all four, the mean of the
  // middle two ratios, and keeps the prior's proportions.
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  const HandModel prior = HandModel::Default(HandSide::kLeft);
  BoneLengthsMm lengths = prior.bone_lengths_mm();
  for (int k = 1; k < kNumHandKeypoints; ++k) lengths[k] *= 1.12;
  const HandModel truth = prior.WithBoneLengths(lengths).value();
  const double seen[4] = {1.0, 0.98, 0.95, 0.85};  // index, middle, ring, little
  std::vector<HandPointsMm> frames;
  for (int f = 0; f < 200; ++f) {
    HandPointsMm p = ForwardKinematics(truth, testing::RandomPose(truth, rng));
    for (int finger = 1; finger <= 4; ++finger) {
      const int k0 = KeypointIndex(static_cast<Finger>(finger), 0);
      const Eigen::Vector3d base =
          p[0] + seen[finger - 1] * (p[k0] - p[0]) + 0.5 * Eigen::Vector3d(n(rng), n(rng), n(rng));
      const Eigen::Vector3d move = base - p[k0];
      for (int j = 0; j < 4; ++j) p[k0 + j] += move;  // the finger's own bones unchanged
    }
    frames.push_back(p);
  }
  BoneLengthOptions each;
  BoneLengthOptions one = each;
  one.palm_as_one = true;
  const StatusOr<BoneLengthEstimate> a = EstimateBoneLengths(frames, prior, each);
  const StatusOr<BoneLengthEstimate> b = EstimateBoneLengths(frames, prior, one);
  ASSERT_TRUE(a.ok() && b.ok());
  double worst_each = 0, worst_one = 0;
  const int index_base = KeypointIndex(Finger::kIndex, 0);
  for (int finger = 1; finger <= 4; ++finger) {
    const int k = KeypointIndex(static_cast<Finger>(finger), 0);
    const double want = truth.bone_length_mm(k);
    worst_each = std::max(worst_each, std::abs(a->lengths_mm[k] / want - 1));
    worst_one = std::max(worst_one, std::abs(b->lengths_mm[k] / want - 1));
    // One scale: the prior's proportions.
    EXPECT_NEAR(b->lengths_mm[k] / b->lengths_mm[index_base],
                prior.bone_length_mm(k) / prior.bone_length_mm(index_base),
                1e-9);
  }
  std::printf("[ palm ] worst palm bone %.1f %% off each by itself, %.1f %% as one piece\n",
              100 * worst_each,
              100 * worst_one);
  EXPECT_GT(worst_each, 0.12);
  EXPECT_LT(worst_one, 0.05);
  for (int k = 1; k < kNumHandKeypoints; ++k) {
    const bool thumb = k <= KeypointIndex(Finger::kThumb, 3);
    if (thumb || ParentKeypoint(k) != 0) {
      EXPECT_EQ(a->lengths_mm[k], b->lengths_mm[k]) << k;
    }
  }
}

TEST(EstimateBoneLengths, FillsUnseenBonesFromScaleAndClampsToAnatomy) {
  std::mt19937 rng(3);
  Capture c = MakeCapture(50, 1.0, rng);
  for (auto& f : c.frames) f[20].setConstant(std::nan(""));  // little tip never seen
  for (size_t i = 0; i < c.frames.size(); ++i) {             // index tip bone absurdly long
    c.frames[i][8] = c.frames[i][7] + Eigen::Vector3d(0, 50, 0);
  }
  const HandModel prior = HandModel::Default(HandSide::kLeft);
  const auto est = EstimateBoneLengths(c.frames, prior, BoneLengthOptions{});
  ASSERT_TRUE(est.ok());
  EXPECT_FALSE(est->from_data[20]);
  EXPECT_NEAR(est->lengths_mm[20], est->hand_scale * prior.bone_length_mm(20), 1e-9);
  EXPECT_TRUE(est->clamped[8]);
  EXPECT_NEAR(est->lengths_mm[8], 1.6 * prior.bone_length_mm(8), 1e-9);
}

TEST(EstimateBoneLengths, ErrorsOnEmptyInputAndWrongUnits) {
  const HandModel prior = HandModel::Default(HandSide::kRight);
  EXPECT_FALSE(EstimateBoneLengths({}, prior, BoneLengthOptions{}).ok());
  std::mt19937 rng(4);
  Capture c = MakeCapture(40, 0.5, rng);
  for (auto& f : c.frames) {
    for (auto& p : f) p *= 2.5;  // not millimetres: 2.5 x every bone
  }
  const auto est = EstimateBoneLengths(c.frames, prior, BoneLengthOptions{});
  ASSERT_FALSE(est.ok());
  EXPECT_NE(est.status().message().find("millimetres"), std::string::npos);
  BoneLengthOptions bad;
  bad.min_ratio = 1.5;
  EXPECT_FALSE(bad.Validate().ok());
  EXPECT_THROW(EstimateBoneLengths(c.frames, prior, bad), std::invalid_argument);
}

}  // namespace
}  // namespace arco::hand
