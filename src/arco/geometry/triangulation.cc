#include "arco/geometry/triangulation.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>

namespace arco {
namespace {

// Adds the two DLT rows of one view, w (x p3 - p1) and w (y p3 - p2), to the
// normal matrix A^T A.
void AccumulateRows(const Matrix34d& p, const Eigen::Vector2d& x, double w, Eigen::Matrix4d* ata) {
  const Eigen::Matrix<double, 1, 4> r0 = w * (x.x() * p.row(2) - p.row(0));
  const Eigen::Matrix<double, 1, 4> r1 = w * (x.y() * p.row(2) - p.row(1));
  ata->noalias() += r0.transpose() * r0 + r1.transpose() * r1;
}

// Smallest right singular vector of A from A^T A; empty when at infinity.
std::optional<Eigen::Vector3d> SolveHomogeneous(const Eigen::Matrix4d& ata) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> solver(ata);
  if (solver.info() != Eigen::Success) return std::nullopt;
  // Eigenvalues are sorted ascending.
  const Eigen::Vector4d h = solver.eigenvectors().col(0);
  if (!h.allFinite() || std::abs(h[3]) < 1e-12 * h.head<3>().norm()) return std::nullopt;
  return Eigen::Vector3d(h.head<3>() / h[3]);
}

// Least-squares point with the last homogeneous coordinate fixed to 1: the 3x3
// normal equations A_3^T A_3 X = -A_3^T a_4 read off A^T A; empty when singular.
std::optional<Eigen::Vector3d> SolveInhomogeneous(const Eigen::Matrix4d& ata) {
  return SolveSymmetric3x3(ata.topLeftCorner<3, 3>(), -ata.topRightCorner<3, 1>());
}

}  // namespace

WorldConditioning ConditioningFromCameraCenters(const std::vector<Eigen::Vector3d>& centers) {
  WorldConditioning c;
  if (centers.empty()) return c;
  // Sum in lexicographic order so the result does not depend on camera order.
  std::vector<Eigen::Vector3d> sorted = centers;
  std::sort(sorted.begin(), sorted.end(), [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  });
  for (const auto& x : sorted) c.center += x;
  c.center /= static_cast<double>(centers.size());
  double sum_sq = 0;
  for (const auto& x : sorted) sum_sq += (x - c.center).squaredNorm();
  const double rms = std::sqrt(sum_sq / static_cast<double>(centers.size()));
  c.scale = (std::isfinite(rms) && rms > 0) ? rms : 1.0;
  return c;
}

Matrix34d ConditionProjection(const Matrix34d& projection, const WorldConditioning& conditioning) {
  Matrix34d out;
  out.leftCols<3>() = projection.leftCols<3>() * conditioning.scale;
  out.col(3) = projection.leftCols<3>() * conditioning.center + projection.col(3);
  return out;
}

std::optional<Eigen::Vector3d> TriangulateDltConditioned(const DltObservation* observations,
                                                         int count,
                                                         const DltOptions& options) {
  int used = 0;
  Eigen::Matrix4d ata = Eigen::Matrix4d::Zero();
  for (int i = 0; i < count; ++i) {
    const DltObservation& o = observations[i];
    if (!(o.weight > 0)) continue;
    AccumulateRows(o.projection, o.point, o.weight, &ata);
    ++used;
  }
  if (used < 2) return std::nullopt;
  auto solve = options.inhomogeneous ? SolveInhomogeneous : SolveHomogeneous;
  std::optional<Eigen::Vector3d> x = solve(ata);
  for (int iter = 0; x && iter < options.reweight_iterations; ++iter) {
    ata.setZero();
    const Eigen::Vector4d xh = x->homogeneous();
    for (int i = 0; i < count; ++i) {
      const DltObservation& o = observations[i];
      if (!(o.weight > 0)) continue;
      const double depth = o.projection.row(2).dot(xh);
      // A point behind a view keeps its unit depth weight; cheirality is the caller's test.
      const double inv_depth = std::abs(depth) > 1e-12 ? 1.0 / std::abs(depth) : 1.0;
      AccumulateRows(o.projection, o.point, o.weight * inv_depth, &ata);
    }
    std::optional<Eigen::Vector3d> next = solve(ata);
    if (!next) break;
    x = next;
  }
  return x;
}

std::optional<Eigen::Vector3d> TriangulateDlt(const std::vector<DltObservation>& observations,
                                              const WorldConditioning& conditioning,
                                              const DltOptions& options) {
  std::vector<DltObservation> conditioned = observations;
  for (auto& o : conditioned) o.projection = ConditionProjection(o.projection, conditioning);
  auto x =
      TriangulateDltConditioned(conditioned.data(), static_cast<int>(conditioned.size()), options);
  if (!x) return std::nullopt;
  return Eigen::Vector3d(conditioning.center + conditioning.scale * *x);
}

std::optional<Eigen::Vector3d> SolveSymmetric3x3(const Eigen::Matrix3d& a,
                                                 const Eigen::Vector3d& b,
                                                 double min_hadamard_ratio) {
  const double diagonal = a(0, 0) * a(1, 1) * a(2, 2);
  if (!(diagonal > 0)) return std::nullopt;
  // Eigen's fixed-size 3x3 determinant and inverse are closed-form (cofactors).
  if (!(a.determinant() > min_hadamard_ratio * diagonal)) return std::nullopt;
  const Eigen::Vector3d x = a.inverse() * b;
  if (!x.allFinite()) return std::nullopt;
  return x;
}

std::optional<Eigen::Vector3d> TriangulateTwoViewsConditioned(const Matrix34d& p0,
                                                              const Eigen::Vector2d& x0,
                                                              const Matrix34d& p1,
                                                              const Eigen::Vector2d& x1) {
  Eigen::Matrix4d a;
  a.row(0) = x0.x() * p0.row(2) - p0.row(0);
  a.row(1) = x0.y() * p0.row(2) - p0.row(1);
  a.row(2) = x1.x() * p1.row(2) - p1.row(0);
  a.row(3) = x1.y() * p1.row(2) - p1.row(1);
  // Four equations, four homogeneous unknowns: the least-squares solution with the
  // last coordinate fixed to 1 solves the 4x3 system A[:, :3] X = -A[:, 3] in the
  // least-squares sense via its 3x3 normal equations.
  const Eigen::Matrix<double, 4, 3> m = a.leftCols<3>();
  const Eigen::Matrix3d mtm = m.transpose() * m;
  const Eigen::Vector3d rhs = -m.transpose() * a.col(3);
  return SolveSymmetric3x3(mtm, rhs);
}

}  // namespace arco
