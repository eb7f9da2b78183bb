// Linear triangulation of one 3D point from several views: the direct linear
// transform (DLT, Hartley & Zisserman, "Multiple View Geometry", 2nd ed., sec. 12.2)
// with per-view confidence weights, world-coordinate conditioning (H&Z sec. 4.4.4)
// and optional iterative depth reweighting (Hartley & Sturm 1997, "iterative linear"),
// which turns the algebraic residual into the image-plane residual.
//
// Conventions: each observation pairs a 3x4 projection matrix P with the image point
// x = (P X).hnormalized(); both must use the same image coordinates. arco passes
// P = [R | t] and undistorted normalised camera coordinates (x = X_cam / Z_cam), so
// the rows are well scaled without image conditioning.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

namespace arco {

using Matrix34d = Eigen::Matrix<double, 3, 4>;

struct DltObservation {
  Matrix34d projection;   // maps homogeneous world points to homogeneous image points
  Eigen::Vector2d point;  // observed image point in P's image coordinates
  double weight = 1.0;    // confidence weight (>= 0), multiplies the view's two rows
};

// Similarity that conditions world coordinates: x_cond = (x_world - center) / scale.
// Choose it so the camera centres (and the scene) sit at O(1) coordinates.
struct WorldConditioning {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double scale = 1.0;
};

// Centroid and RMS distance of the given camera centres (scale 1 when degenerate).
WorldConditioning ConditioningFromCameraCenters(const std::vector<Eigen::Vector3d>& centers);

// Rewrites P (world -> image) as P' (conditioned world -> image): P' = P * S with
// S = [scale * I, center; 0, 1].
Matrix34d ConditionProjection(const Matrix34d& projection, const WorldConditioning& conditioning);

struct DltOptions {
  // Extra solves that divide each view's rows by its depth (P X)_3 from the previous
  // estimate, so the minimised quantity approaches the image-plane error.
  int reweight_iterations = 1;
  // Fix the homogeneous coordinate to 1 and solve the 3x3 normal equations by LDLT
  // (H&Z sec. 12.2, "inhomogeneous method") instead of taking the smallest eigenvector
  // of the 4x4 A^T A: several times cheaper, and in conditioned coordinates the same
  // point to well below the noise for points at finite distance; not for points at or
  // near infinity, which it reports as empty (ill-conditioned system).
  bool inhomogeneous = false;
};

// Weighted DLT in conditioned coordinates: `observations` must already use
// conditioned projection matrices (ConditionProjection); the result is in the
// conditioned frame too. Empty when fewer than two observations carry positive
// weight or the solution lies at infinity (rays parallel). Does not allocate.
std::optional<Eigen::Vector3d> TriangulateDltConditioned(const DltObservation* observations,
                                                         int count,
                                                         const DltOptions& options = DltOptions());

// Convenience: conditions, solves, and maps the point back to world coordinates.
std::optional<Eigen::Vector3d> TriangulateDlt(const std::vector<DltObservation>& observations,
                                              const WorldConditioning& conditioning,
                                              const DltOptions& options = DltOptions());

// Solves the symmetric 3x3 system A x = b with Eigen's closed-form 3x3 inverse (the
// adjugate): a few dozen flops where a pivoted factorisation spends most of its time in
// loop overhead.
// For positive (semi)definite A (normal equations). Empty when A is numerically
// singular: for a positive definite A,
// 0 < det(A) <= A00 A11 A22 (Hadamard's inequality, equality when A is diagonal), so the
// ratio det(A) / (A00 A11 A22) is a scale-free measure of how far A is from singular,
// and the solve is refused below `min_hadamard_ratio`.
std::optional<Eigen::Vector3d> SolveSymmetric3x3(const Eigen::Matrix3d& a,
                                                 const Eigen::Vector3d& b,
                                                 double min_hadamard_ratio = 1e-13);

// Closed-form two-view triangulation (same as TriangulateDltConditioned on two
// observations with unit weights); the RANSAC hypothesis generator.
std::optional<Eigen::Vector3d> TriangulateTwoViewsConditioned(const Matrix34d& p0,
                                                              const Eigen::Vector2d& x0,
                                                              const Matrix34d& p1,
                                                              const Eigen::Vector2d& x1);

}  // namespace arco
