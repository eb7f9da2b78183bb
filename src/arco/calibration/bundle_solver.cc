#include "arco/calibration/bundle_solver.h"

#include <utility>

namespace arco::calibration {

StatusOr<BundleAdjustmentSummary> SolveBundle(
    ceres::Problem* problem,
    std::shared_ptr<ceres::ParameterBlockOrdering> ordering,
    int max_iterations,
    std::chrono::steady_clock::time_point start) {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_SCHUR;
  options.linear_solver_ordering = std::move(ordering);
  options.max_num_iterations = max_iterations;
  options.function_tolerance = 1e-10;
  options.gradient_tolerance = 1e-12;
  options.parameter_tolerance = 1e-10;
  // One thread: Ceres's multi-threaded Schur elimination sums in a varying order, and the
  // result must not depend on the thread count.
  options.num_threads = 1;
  ceres::Solver::Summary solved;
  ceres::Solve(options, problem, &solved);
  if (solved.termination_type == ceres::FAILURE)
    return Status::Error("bundle adjustment failed: " + solved.message);
  BundleAdjustmentSummary summary;
  summary.termination = ceres::TerminationTypeToString(solved.termination_type);
  summary.iterations = static_cast<int>(solved.iterations.size()) - 1;
  summary.initial_cost = solved.initial_cost;
  summary.final_cost = solved.final_cost;
  summary.residual_blocks = solved.num_residual_blocks;
  summary.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace arco::calibration
