// ReprojectionProblem against the block it stands for (HandCostFunction over all
// observations): Levenberg-Marquardt sees a block only through |r|^2, J^T r and J^T J,
// so those must agree (but in the rows and columns of locked joints, which the problem
// holds at 0), also when a finger is seen in no view (J^T J singular).
#include "arco/hand/fit_costs.h"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <random>

#include "arco/hand/hand_test_util.h"
#include "arco/hand/synthetic_rig.h"

namespace arco::hand::internal {
namespace {

// The reference: the same residuals as a ceres::CostFunction (what the fits solved with
// before issue 28 part 3). Jacobians by the chain rule: keypoint Jacobians from the kinematic tree
// (HandPointsAndJacobians), times the 2x3 (projection + robust scaling) or 3x3
// (robust scaling) derivative of each residual with respect to its keypoint,
// both from small Jets. Values come from the templated residual functors.
template <typename Residuals>
class HandCostFunction : public ceres::CostFunction {
 public:
  explicit HandCostFunction(Residuals residuals) : r_(residuals) {
    set_num_residuals(r_.num_residuals());
    mutable_parameter_block_sizes()->assign({3, 3, kNumJointDofs});
  }
  ARCO_FLATTEN bool Evaluate(double const* const* x,
                             double* residuals,
                             double** jacobians) const override {
    if (jacobians == nullptr) {
      r_(x[0], x[1], x[2], residuals);
      return true;
    }
    Eigen::Vector3d points[kNumHandKeypoints];
    HandPointJacobian point_jacobians[kNumHandKeypoints];
    HandPointsAndJacobians(*r_.model, x[0], x[1], x[2], points, point_jacobians);
    const int sizes[3] = {3, 3, kNumJointDofs};
    const int offsets[3] = {0, 3, 6};
    Eigen::Matrix<double, 3, 3> d_residual;  // rows: residual components (<= 3)
    int row = 0;
    for (int i = 0; row < num_residuals(); ++i) {
      int keypoint;
      const int dim = r_.ResidualWithDerivative(i, points, residuals + row, &d_residual, &keypoint);
      for (int j = 0; j < dim; ++j, ++row) {
        const Eigen::Matrix<double, 1, 6 + kNumJointDofs> d =
            d_residual.row(j) * point_jacobians[keypoint];
        for (int b = 0; b < 3; ++b) {
          if (jacobians[b] == nullptr) continue;
          for (int c = 0; c < sizes[b]; ++c) jacobians[b][row * sizes[b] + c] = d[offsets[b] + c];
        }
      }
    }
    return true;
  }

 private:
  Residuals r_;
};

constexpr int kParams = ReprojectionProblem::kParams;
using Mat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

struct Normal {
  double rr = 0;
  Eigen::MatrixXd jtj;
  Eigen::VectorXd jtr;
};

// |r|^2, J^T J, J^T r of a cost function with the (aa, t, angles) blocks.

Normal Evaluate(const ceres::CostFunction& f, const double* aa, const double* t,
                const double* angles) {
  const int m = f.num_residuals();
  Eigen::VectorXd r(m);
  Mat j0(m, 3), j1(m, 3), j2(m, kNumJointDofs);
  const double* x[3] = {aa, t, angles};
  double* jac[3] = {j0.data(), j1.data(), j2.data()};
  EXPECT_TRUE(f.Evaluate(x, r.data(), jac));
  Eigen::MatrixXd j(m, kParams);
  j << j0, j1, j2;
  Normal n;
  n.rr = r.squaredNorm();
  n.jtj = j.transpose() * j;
  n.jtr = j.transpose() * r;
  Eigen::VectorXd cost_only(m);
  EXPECT_TRUE(f.Evaluate(x, cost_only.data(), nullptr));
  EXPECT_NEAR(cost_only.squaredNorm(), n.rr, 1e-9 * n.rr);
  return n;
}

void ExpectSameNormalEquations(bool hide_a_finger) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::mt19937 rng(hide_a_finger ? 7 : 3);
  const std::vector<Camera> cameras = testing::MakeRingRig(20, 2500, Eigen::Vector3d::Zero());
  const HandPose truth = testing::RandomPose(model, rng, 0.1);
  const auto views = testing::ProjectHand(cameras, ForwardKinematics(model, truth), 2.0, 0.1, rng);
  std::vector<PixelObservation> observations;
  for (size_t v = 0; v < views.size(); ++v) {
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      if (hide_a_finger && k >= 13 && k <= 16) continue;  // the ring finger, in every view
      if (!views[v].pixels[k].allFinite()) continue;
      observations.push_back({&cameras[v], static_cast<int>(v), k, views[v].pixels[k],
                              std::sqrt(views[v].scores[k])});
    }
  }
  // Evaluated away from the truth, as in the solver's first iterations.
  HandPose start = truth;
  start.world_from_wrist.translation += Eigen::Vector3d(4, -3, 5);
  for (double& a : start.angles_rad) a += 0.05;
  start = ClampToLimits(model, start);
  const Eigen::Vector3d aa = start.WristAngleAxis();
  const ReprojectionResiduals residuals{&model, &observations, 5.0 * 5.0};
  Normal full = Evaluate(HandCostFunction<ReprojectionResiduals>(residuals),
                         aa.data(),
                         start.world_from_wrist.translation.data(),
                         start.angles_rad.data());
  ReprojectionProblem::Vector x;
  x.head<6>() << aa, start.world_from_wrist.translation;
  for (int d = 0; d < kNumJointDofs; ++d) x[6 + d] = start.angles_rad[d];
  ReprojectionProblem::Matrix h;
  ReprojectionProblem::Vector g;
  const Eigen::MatrixXd full_jtj = full.jtj;  // before the locked joints' rows go
  Normal compressed;
  compressed.rr = 2 * ReprojectionProblem(residuals, nullptr).Evaluate(x, &h, &g);
  compressed.jtj = h;
  compressed.jtr = g;
  for (int d = 0; d < kNumJointDofs; ++d) {
    if (model.max_rad(d) - model.min_rad(d) >= 1e-12) continue;
    EXPECT_EQ(compressed.jtj.row(6 + d).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(compressed.jtr[6 + d], 0.0);
    full.jtj.row(6 + d).setZero();
    full.jtj.col(6 + d).setZero();
    full.jtr[6 + d] = 0;
  }
  EXPECT_NEAR(compressed.rr, full.rr, 1e-9 * full.rr);
  const double scale = full.jtj.cwiseAbs().maxCoeff();
  EXPECT_LT((compressed.jtj - full.jtj).cwiseAbs().maxCoeff(), 1e-10 * scale);
  EXPECT_LT((compressed.jtr - full.jtr).cwiseAbs().maxCoeff(),
            1e-9 * full.jtr.cwiseAbs().maxCoeff());
  // The hidden finger's angles are unconstrained: J^T J is singular there.
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(full_jtj);
  if (hide_a_finger) {
    EXPECT_LT(eig.eigenvalues()[0], 1e-12 * eig.eigenvalues().maxCoeff());
  } else {
    EXPECT_GT(eig.eigenvalues()[0], 1e-9 * eig.eigenvalues().maxCoeff());
  }
}

TEST(ReprojectionProblem, SameNormalEquationsAsTheFullBlock) { ExpectSameNormalEquations(false); }

TEST(ReprojectionProblem, SameNormalEquationsWhenAFingerIsSeenInNoView) {
  ExpectSameNormalEquations(true);
}

// PointProblem (the 3D initialisation's) against HandCostFunction<PointResiduals>, with
// missing points, and the temporal prior's terms against its autodiff cost function.
TEST(PointProblem, SameNormalEquationsAsTheCostFunctionsWithTheTemporalPrior) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::mt19937 rng(5);
  const HandPose truth = testing::RandomPose(model, rng, 0.1);
  HandPointsMm targets = ForwardKinematics(model, truth);
  targets[7] = targets[18] = Eigen::Vector3d::Constant(std::nan(""));
  targets[3] += Eigen::Vector3d(30, -20, 10);  // an outlier, on the Cauchy loss's tail
  HandPose start = truth;
  start.world_from_wrist.translation += Eigen::Vector3d(4, -3, 5);
  for (double& a : start.angles_rad) a += 0.05;
  start = ClampToLimits(model, start);
  const Eigen::Vector3d aa = start.WristAngleAxis();
  const PointResiduals residuals{&model, &targets, 10.0 * 10.0};
  const TemporalResiduals temporal{truth.world_from_wrist.rotation,
                                   truth.world_from_wrist.translation,
                                   truth.angles_rad,
                                   2.0,
                                   0.5,
                                   3.0};
  Normal full = Evaluate(HandCostFunction<PointResiduals>(residuals),
                         aa.data(),
                         start.world_from_wrist.translation.data(),
                         start.angles_rad.data());
  const Normal prior =
      Evaluate(ceres::AutoDiffCostFunction<TemporalResiduals, kParams, 3, 3, kNumJointDofs>(
                   new TemporalResiduals(temporal)),
               aa.data(),
               start.world_from_wrist.translation.data(),
               start.angles_rad.data());
  full.rr += prior.rr;
  full.jtj += prior.jtj;
  full.jtr += prior.jtr;
  PointProblem::Vector x;
  x.head<6>() << aa, start.world_from_wrist.translation;
  for (int d = 0; d < kNumJointDofs; ++d) x[6 + d] = start.angles_rad[d];
  PointProblem::Matrix h;
  PointProblem::Vector g;
  const double rr = 2 * PointProblem(residuals, &temporal).Evaluate(x, &h, &g);
  for (int d = 0; d < kNumJointDofs; ++d) {
    if (model.max_rad(d) - model.min_rad(d) >= 1e-12) continue;
    full.jtj.row(6 + d).setZero();
    full.jtj.col(6 + d).setZero();
    full.jtr[6 + d] = 0;
  }
  EXPECT_NEAR(rr, full.rr, 1e-9 * full.rr);
  EXPECT_LT((h - full.jtj).cwiseAbs().maxCoeff(), 1e-10 * full.jtj.cwiseAbs().maxCoeff());
  EXPECT_LT((g - full.jtr).cwiseAbs().maxCoeff(), 1e-9 * full.jtr.cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace arco::hand::internal
