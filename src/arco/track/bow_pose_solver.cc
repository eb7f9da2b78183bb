#include "arco/track/bow_pose_solver.h"

#include <ceres/ceres.h>
#include <ceres/cubic_interpolation.h>

#include <limits>
#include <memory>

namespace arco::track {
namespace {

using Interpolator = ceres::BiCubicInterpolator<ceres::Grid2D<float, 1>>;

// The point X + u d.
template <typename T>
void AlongStick(const T* frog, const T* direction, double u, T* x) {
  for (int i = 0; i < 3; ++i) x[i] = frog[i] + T(u) * direction[i];
}

// Perpendicular distance (ideal pixels) of a stick point's pinhole projection to the
// view's fitted line: the lines were fitted to undistorted segment end points.
struct LineResidual {
  const Camera* camera;
  double u;
  Eigen::Vector2d point, normal;
  double scale;  // weight / sigma
  template <typename T>
  bool operator()(const T* frog, const T* direction, T* residual) const {
    T x[3];
    AlongStick(frog, direction, u, x);
    T c[3];
    for (int r = 0; r < 3; ++r) {
      c[r] = T(camera->cam_from_world.translation[r]);
      for (int k = 0; k < 3; ++k) c[r] += T(camera->cam_from_world.rotation(r, k)) * x[k];
    }
    if (!(c[2] > T(1e-6))) return false;
    const T xn = c[0] / c[2], yn = c[1] / c[2];
    const T px = T(camera->fx) * xn + T(camera->skew) * yn + T(camera->cx);
    const T py = T(camera->fy) * yn + T(camera->cy);
    residual[0] =
        T(scale) * (T(normal.x()) * (px - T(point.x())) + T(normal.y()) * (py - T(point.y())));
    return true;
  }
};

// The frame's intensity at the distorted projection of X + u d (bicubic on the blurred
// box) plus the view's brightness offset, against the labelled frame's.
struct IntensityResidual {
  const Camera* camera;
  const Interpolator* image;
  double x0, y0;
  double u, value;
  double scale;  // 1 / sigma
  template <typename T>
  bool operator()(const T* frog, const T* direction, const T* offset, T* residual) const {
    T x[3];
    AlongStick(frog, direction, u, x);
    T pixel[2];
    if (!camera->ProjectToPixel(x, pixel)) return false;
    T intensity;
    image->Evaluate(pixel[1] - T(y0), pixel[0] - T(x0), &intensity);
    residual[0] = T(scale) * (intensity + offset[0] - T(value));
    return true;
  }
};

struct PointPriorResidual {
  double u;
  Eigen::Vector3d target;
  double scale;
  template <typename T>
  bool operator()(const T* frog, const T* direction, T* residual) const {
    T x[3];
    AlongStick(frog, direction, u, x);
    for (int i = 0; i < 3; ++i) residual[i] = T(scale) * (x[i] - T(target[i]));
    return true;
  }
};

}  // namespace

BowPose SolveBowPose(const std::vector<BowViewTerms>& views,
                     const std::vector<BowPointPrior>& priors,
                     double length,
                     const BowPose& start,
                     const BowSolveOptions& options) {
  double frog[3] = {start.frog.x(), start.frog.y(), start.frog.z()};
  const Eigen::Vector3d d0 = start.direction.normalized();
  double direction[3] = {d0.x(), d0.y(), d0.z()};
  std::vector<double> offsets(views.size(), 0.0);
  std::vector<std::unique_ptr<ceres::Grid2D<float, 1>>> grids;
  std::vector<std::unique_ptr<Interpolator>> interpolators;

  ceres::Problem problem;
  problem.AddParameterBlock(frog, 3);
  problem.AddParameterBlock(direction, 3, new ceres::SphereManifold<3>());
  for (size_t v = 0; v < views.size(); ++v) {
    const BowViewTerms& view = views[v];
    if (view.line_weight > 0) {
      const Eigen::Vector2d n(-view.line_direction.y(), view.line_direction.x());
      for (int i = 0; i < options.line_points; ++i) {
        const double u = length * i / std::max(1, options.line_points - 1);
        auto* cost = new ceres::AutoDiffCostFunction<LineResidual, 1, 3, 3>(new LineResidual{
            view.camera, u, view.line_point, n, view.line_weight / options.line_sigma_px});
        problem.AddResidualBlock(cost, new ceres::HuberLoss(1.0), frog, direction);
      }
    }
    if (view.image != nullptr && !view.u.empty()) {
      grids.push_back(
          std::make_unique<ceres::Grid2D<float, 1>>(view.image, 0, view.rows, 0, view.cols));
      interpolators.push_back(std::make_unique<Interpolator>(*grids.back()));
      problem.AddParameterBlock(&offsets[v], 1);
      for (size_t k = 0; k < view.u.size(); ++k) {
        auto* cost = new ceres::AutoDiffCostFunction<IntensityResidual, 1, 3, 3, 1>(
            new IntensityResidual{view.camera,
                                  interpolators.back().get(),
                                  static_cast<double>(view.x0),
                                  static_cast<double>(view.y0),
                                  view.u[k],
                                  view.value[k],
                                  1.0 / options.intensity_sigma});
        problem.AddResidualBlock(cost, new ceres::HuberLoss(1.0), frog, direction, &offsets[v]);
      }
    }
  }
  for (const BowPointPrior& p : priors) {
    if (!(p.sigma_mm > 0) || !p.target.allFinite()) continue;
    auto* cost = new ceres::AutoDiffCostFunction<PointPriorResidual, 3, 3, 3>(
        new PointPriorResidual{p.u, p.target, 1.0 / p.sigma_mm});
    problem.AddResidualBlock(cost, nullptr, frog, direction);
  }
  BowPose out = start;
  out.direction = d0;
  if (problem.NumResidualBlocks() == 0) return out;
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = options.max_iterations;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  out.frog = Eigen::Vector3d(frog[0], frog[1], frog[2]);
  out.direction = Eigen::Vector3d(direction[0], direction[1], direction[2]).normalized();
  out.cost = summary.final_cost;
  out.usable = summary.IsSolutionUsable() && out.frog.allFinite() && out.direction.allFinite();
  return out;
}

std::vector<double> SampleStick(const Camera& camera,
                                const float* image,
                                int rows,
                                int cols,
                                int x0,
                                int y0,
                                const Eigen::Vector3d& frog,
                                const Eigen::Vector3d& direction,
                                const std::vector<double>& u) {
  std::vector<double> out(u.size(), std::numeric_limits<double>::quiet_NaN());
  if (image == nullptr || rows < 5 || cols < 5) return out;
  const ceres::Grid2D<float, 1> grid(image, 0, rows, 0, cols);
  const Interpolator interpolator(grid);
  for (size_t k = 0; k < u.size(); ++k) {
    const auto p = camera.Project(frog + u[k] * direction);
    if (!p) continue;
    const double c = p->x() - x0, r = p->y() - y0;
    if (!(c >= 2 && r >= 2 && c <= cols - 3 && r <= rows - 3)) continue;
    interpolator.Evaluate(r, c, &out[k]);
  }
  return out;
}

}  // namespace arco::track
