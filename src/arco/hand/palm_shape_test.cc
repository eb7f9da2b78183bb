#include "arco/hand/palm_shape.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "arco/geometry/rotation.h"
#include "arco/hand/kinematics.h"

namespace arco::hand {
namespace {

// Frames of a hand whose palm differs from the model's by known base moves, seen in
// random poses with independent noise per point: the estimate must find the moves.
struct Take {
  std::vector<HandPointsMm> frames;
  std::array<Eigen::Vector3d, kNumFingers> true_bases;
};

Take MakeTake(const HandModel& model,
              const std::array<Eigen::Vector3d, kNumFingers>& moves,
              int n,
              double noise_mm,
              double outlier_rate,
              uint32_t seed) {
  Take take;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_mm);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int f = 0; f < kNumFingers; ++f) {
    take.true_bases[f] = model.rest_point_mm(KeypointIndex(static_cast<Finger>(f), 0)) + moves[f];
  }
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d axis(unit(rng), unit(rng), unit(rng));
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(2.0 * unit(rng), axis.normalized()).toRotationMatrix();
    const Eigen::Vector3d t(300 * unit(rng), 300 * unit(rng), 1000 + 100 * unit(rng));
    HandPointsMm p;
    for (auto& x : p) x.setConstant(std::nan(""));
    p[0] = t;
    for (int f = 0; f < kNumFingers; ++f) {
      p[KeypointIndex(static_cast<Finger>(f), 0)] = r * take.true_bases[f] + t;
    }
    for (auto& x : p) {
      if (!x.allFinite()) continue;
      x += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
      if (std::abs(unit(rng)) < outlier_rate) x += Eigen::Vector3d(60, -40, 50);
    }
    take.frames.push_back(p);
  }
  return take;
}

TEST(PalmShape, FindsThePerformersBasesUnderNoiseAndOutliers) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  const std::array<Eigen::Vector3d, kNumFingers> moves = {Eigen::Vector3d(2, 1, 3),
                                                          Eigen::Vector3d(-1, 2, 1),
                                                          Eigen::Vector3d(-3, 1, -1),
                                                          Eigen::Vector3d(-1, 2, 1),
                                                          Eigen::Vector3d(2, 1, 3)};
  const Take take = MakeTake(model, moves, 1600, 2.0, 0.02, 7);
  StatusOr<PalmShapeEstimate> est = EstimatePalmShape(take.frames, model, PalmShapeOptions());
  ASSERT_TRUE(est.ok()) << est.status().message();
  // The frame convention: the estimate is turned onto the model's bases, so compare after
  // the same turn of the truth (a rigid turn of the true palm is the same palm).
  std::vector<Eigen::Vector3d> truth, model_bases;
  for (int f = 0; f < kNumFingers; ++f) {
    truth.push_back(take.true_bases[f]);
    model_bases.push_back(model.rest_point_mm(KeypointIndex(static_cast<Finger>(f), 0)));
  }
  const Eigen::Matrix3d turn = KabschRotation(truth, model_bases);
  for (int f = 0; f < kNumFingers; ++f) {
    const Eigen::Vector3d expected = turn * take.true_bases[f];
    const double model_error = (model_bases[f] - expected).norm();
    const double error = (est->base_in_wrist_mm[f] - expected).norm();
    EXPECT_LT(error, 0.5) << "finger " << f;
    EXPECT_LT(error, 0.3 * model_error) << "finger " << f;
    EXPECT_EQ(est->kept_model[f], 0);
  }
  EXPECT_GT(est->frames_used, 1300);  // the outlier frames are gated away, not all
  EXPECT_LT(est->frames_used, 1600);
}

TEST(PalmShape, TheModelsOwnPalmStaysPut) {
  const HandModel model = HandModel::Default(HandSide::kRight);
  std::array<Eigen::Vector3d, kNumFingers> none;
  for (auto& m : none) m.setZero();
  const Take take = MakeTake(model, none, 200, 1.0, 0.0, 3);
  StatusOr<PalmShapeEstimate> est = EstimatePalmShape(take.frames, model, PalmShapeOptions());
  ASSERT_TRUE(est.ok()) << est.status().message();
  for (int f = 0; f < kNumFingers; ++f) EXPECT_LT(est->shift_mm[f], 0.5) << f;
}

TEST(PalmShape, ABaseFarOffKeepsTheModelsAndTooFewFramesIsAnError) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::array<Eigen::Vector3d, kNumFingers> moves;
  for (auto& m : moves) m.setZero();
  moves[4] = Eigen::Vector3d(0, 25, 0);  // a little finger's base 25 mm off: not a palm
  const Take take = MakeTake(model, moves, 100, 0.5, 0.0, 5);
  StatusOr<PalmShapeEstimate> est = EstimatePalmShape(take.frames, model, PalmShapeOptions());
  ASSERT_TRUE(est.ok()) << est.status().message();
  EXPECT_EQ(est->kept_model[4], 1);
  EXPECT_EQ(est->base_in_wrist_mm[4], model.rest_point_mm(KeypointIndex(Finger::kLittle, 0)));
  EXPECT_GT(est->shift_mm[4], 12.0);

  const std::vector<HandPointsMm> few(take.frames.begin(), take.frames.begin() + 10);
  StatusOr<PalmShapeEstimate> none = EstimatePalmShape(few, model, PalmShapeOptions());
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.status().message().find("10 frames"), std::string::npos)
      << none.status().message();
  PalmShapeOptions bad;
  bad.max_shift_mm = std::nan("");
  EXPECT_FALSE(EstimatePalmShape(take.frames, model, bad).ok());
}

TEST(HandModel, WithBasePointsMovesEachFingerWithItsBaseAndKeepsTheAxes) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::array<Eigen::Vector3d, kNumFingers> bases;
  for (int f = 0; f < kNumFingers; ++f) {
    bases[f] = model.rest_point_mm(KeypointIndex(static_cast<Finger>(f), 0)) +
               Eigen::Vector3d(f, -1.0, 0.5 * f);
  }
  StatusOr<HandModel> moved = model.WithBasePoints(bases);
  ASSERT_TRUE(moved.ok()) << moved.status().message();
  for (int f = 0; f < kNumFingers; ++f) {
    const Eigen::Vector3d shift(f, -1.0, 0.5 * f);
    for (int j = 0; j < 4; ++j) {
      const int k = KeypointIndex(static_cast<Finger>(f), j);
      EXPECT_LT((moved->rest_point_mm(k) - model.rest_point_mm(k) - shift).norm(), 1e-9) << k;
    }
  }
  for (int d = 0; d < kNumJointDofs; ++d) EXPECT_LT((moved->axis(d) - model.axis(d)).norm(), 1e-12);
  // The stored rest points rebuild the same model bit for bit.
  StatusOr<HandModel> again = model.WithRestPoints(moved->rest_points_mm());
  ASSERT_TRUE(again.ok());
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    EXPECT_EQ(again->rest_offset_mm(k), moved->rest_offset_mm(k)) << k;
  }
}

}  // namespace
}  // namespace arco::hand
