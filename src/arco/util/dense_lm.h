// A small dense Levenberg-Marquardt loop with Ceres' trust-region and stopping rules, for
// per-frame fits of a few dozen parameters where a ceres::Problem's set-up, checks and
// bookkeeping cost more than the arithmetic (docs/performance.md, issue 28 part 3).
//
// The problem supplies, for its vector type V and matrix type M (Eigen, fixed or dynamic):
//   double Evaluate(const V& x, M* h, V* g);  // cost 1/2 |r|^2 (robust), J^T J (full,
//                                             // symmetric) and J^T r at x; may be +inf
//   bool SolveDamped(M& damped, const V& g, V* step);  // step = -damped^-1 g; damped (h
//                                             // plus Marquardt's diagonal) may be
//                                             // overwritten; false: not positive definite
//   void Plus(const V& x, const V& step, V* candidate);  // x + step (projected on bounds)
//
// Rules, as Ceres' TrustRegionMinimizer with its LEVENBERG_MARQUARDT strategy:
// Marquardt's diagonal diag(J^T J) clamped to [1e-6, 1e32] and divided by the radius
// (starting at initial_radius, at most 1e16), the step accepted when its cost decrease is
// more than 1e-3 of the model's, the radius then divided by max(1/3, 1 - (2 q - 1)^3) (q the
// step quality), else divided by a factor that doubles on each rejection in a row. Stops
// when the gradient's max norm is at most gradient_tolerance, the step's norm at most
// parameter_tolerance (|x| + parameter_tolerance), the cost's change (accepted or not) at
// most function_tolerance times the cost, the radius below 1e-32, or after max_iterations
// steps. Unlike Ceres: the Jacobian is evaluated with every candidate's cost (one
// evaluation per step instead of two when the step is accepted, the usual case), and
// (keep_last_step) a step that meets the function tolerance is kept when it lowered the
// cost.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace arco {

struct DenseLmOptions {
  int max_iterations = 50;
  double function_tolerance = 1e-6;
  double gradient_tolerance = 1e-10;
  double parameter_tolerance = 1e-8;
  double initial_radius = 1e4;
  // Whether a step that meets the function tolerance is kept when it lowered the cost
  // (false: the solve ends at the point before it, as Ceres does).
  bool keep_last_step = true;
};

struct DenseLmSummary {
  int steps = 0;  // steps tried (Ceres' summary.iterations.size() - 1)
  double initial_cost = 0;
  double final_cost = 0;
  bool converged = false;  // false: max_iterations ran out (Ceres' NO_CONVERGENCE)
};

// Scratch (h, g, candidate, ...) is kept between Minimize calls: dynamic sizes allocate
// once per solver, not per frame.
template <typename V, typename M>
class DenseLm {
 public:
  template <typename Problem>
  DenseLmSummary Minimize(Problem& problem, const DenseLmOptions& options, V* x) {
    DenseLmSummary summary;
    double cost = problem.Evaluate(*x, &h_, &g_);
    summary.initial_cost = cost;
    double radius = options.initial_radius;
    double decrease = 2;
    const int size = static_cast<int>(x->size());
    summary.converged = true;
    for (int iteration = 0;; ++iteration) {
      if (iteration == options.max_iterations) {
        summary.converged = false;
        break;
      }
      if (!(g_.template lpNorm<Eigen::Infinity>() > options.gradient_tolerance)) break;
      ++summary.steps;
      damped_ = h_;
      for (int i = 0; i < size; ++i) damped_(i, i) += std::clamp(h_(i, i), 1e-6, 1e32) / radius;
      if (!problem.SolveDamped(damped_, g_, &step_)) {
        radius /= decrease;
        decrease *= 2;
        if (radius < 1e-32) break;
        continue;
      }
      if (!(step_.norm() > options.parameter_tolerance * (x->norm() + options.parameter_tolerance)))
        break;
      problem.Plus(*x, step_, &candidate_);
      const double candidate_cost = problem.Evaluate(candidate_, &candidate_h_, &candidate_g_);
      h_step_.noalias() = h_ * step_;
      const double model_decrease = -(g_.dot(step_) + 0.5 * step_.dot(h_step_));
      const double change = cost - candidate_cost;
      const double quality = change / model_decrease;
      const bool success = std::isfinite(candidate_cost) && model_decrease > 0 && quality > 1e-3;
      // The cost before the step, as candidate_cost + change when it succeeded (FitSkeleton's
      // outputs stay bit-identical to its own loop's).
      const bool converged = std::abs(change) <= options.function_tolerance *
                                                     (success ? candidate_cost + change : cost);
      if (success && (options.keep_last_step || !converged)) {
        x->swap(candidate_);
        h_.swap(candidate_h_);
        g_.swap(candidate_g_);
        cost = candidate_cost;
      }
      if (converged) break;
      if (success) {
        const double t = 2 * quality - 1;
        radius = std::min(1e16, radius / std::max(1.0 / 3.0, 1.0 - t * t * t));
        decrease = 2;
      } else {
        radius /= decrease;
        decrease *= 2;
        if (radius < 1e-32) break;
      }
    }
    summary.final_cost = cost;
    return summary;
  }

 private:
  M h_, candidate_h_, damped_;
  V g_, candidate_g_, candidate_, step_, h_step_;
};

}  // namespace arco
