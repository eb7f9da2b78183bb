#include "arco/hand/ik.h"

#include <ceres/jet.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "arco/hand/kinematics.h"
#include "arco/util/check.h"
#include "arco/util/dense_lm.h"

namespace arco::hand {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kActiveTolRad = 1e-6;
// Grid levels per free joint for restarts, by number of free joints (<= 1296 points).
constexpr int kAutoSeedLevels[5] = {2, 33, 17, 9, 6};

struct SolveOutcome {
  std::vector<double> x;
  double distance_mm = 0;
  double regularisation = 0;  // sum of squared anchor residuals (unscaled weights)
  bool converged = false;
  int iterations = 0;
  int solves = 0;
  std::string termination;
};

struct IkProblemSpec {
  const HandModel* model;
  Finger finger;
  std::array<double, 4> reference;  // clamped reference dofs of the finger
  std::vector<int> slots;
  std::vector<double> lower, upper, ref_free, prev_free;
  bool has_prev = false;
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation, target;
  double pip_weight = 0;  // FingerIkOptions::pip_weight (0 without a PIP target)
  Eigen::Vector3d pip_target = Eigen::Vector3d::Zero();
  double dip_weight = 0;  // FingerIkOptions::dip_weight (0 without a DIP target)
  Eigen::Vector3d dip_target = Eigen::Vector3d::Zero();
};

double TipDistance(const IkProblemSpec& s, const std::vector<double>& x) {
  std::array<double, 4> dof = s.reference;
  for (size_t i = 0; i < s.slots.size(); ++i) dof[s.slots[i]] = x[i];
  Eigen::Vector3d p[4];
  FingerPointsInWrist(*s.model, s.finger, dof.data(), p);
  return (s.rotation * p[3] + s.translation - s.target).norm();
}

// The squared PIP and DIP terms: weight times the keypoint's distance from its target
// (0 without a target).
double KeypointTerms(const IkProblemSpec& s, const std::vector<double>& x) {
  if (s.pip_weight <= 0 && s.dip_weight <= 0) return 0.0;
  std::array<double, 4> dof = s.reference;
  for (size_t i = 0; i < s.slots.size(); ++i) dof[s.slots[i]] = x[i];
  Eigen::Vector3d p[4];
  FingerPointsInWrist(*s.model, s.finger, dof.data(), p);
  return std::pow(s.pip_weight * (s.rotation * p[1] + s.translation - s.pip_target).norm(), 2) +
         std::pow(s.dip_weight * (s.rotation * p[2] + s.translation - s.dip_target).norm(), 2);
}

// The free angles (at most 4) and their normal equations, fixed-capacity (no allocation).
using IkVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 4, 1>;
using IkMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 4, 4>;

// The cost of the header's comment as a least-squares problem for DenseLm: the tip's 3
// residuals (mm, world), the PIP's and DIP's weighted 3 each (zero without a target), and
// the anchors w_ref (x - x_ref) and w_prev (x - x_prev). The 9 x n Jacobian of the
// keypoint residuals comes from 4-Jets through the finger's forward kinematics; J^T J and
// J^T r are summed from it and the anchors' diagonal.
class IkProblem {
 public:
  IkProblem(const IkProblemSpec& s, double w_ref, double w_prev)
      : s_(s), w_ref2_(w_ref * w_ref), w_prev2_(s.has_prev ? w_prev * w_prev : 0.0) {}

  double Evaluate(const IkVector& x, IkMatrix* h, IkVector* g) const {
    using Jet = ceres::Jet<double, 4>;
    const int n = static_cast<int>(x.size());
    Jet dof[4];
    for (int i = 0; i < 4; ++i) dof[i] = Jet(s_.reference[i]);
    for (int i = 0; i < n; ++i) dof[s_.slots[i]] = Jet(x[i], i);
    Eigen::Matrix<Jet, 3, 1> p[4];
    FingerPointsInWrist(*s_.model, s_.finger, dof, p);
    const Eigen::Matrix<Jet, 3, 3> rotation = s_.rotation.cast<Jet>();
    Eigen::Matrix<Jet, 9, 1> r;
    r.segment<3>(0) = rotation * p[3] + (s_.translation - s_.target).cast<Jet>();
    r.segment<3>(3) =
        (rotation * p[1] + (s_.translation - s_.pip_target).cast<Jet>()) * Jet(s_.pip_weight);
    r.segment<3>(6) =
        (rotation * p[2] + (s_.translation - s_.dip_target).cast<Jet>()) * Jet(s_.dip_weight);
    Eigen::Matrix<double, 9, Eigen::Dynamic, 0, 9, 4> jacobian(9, n);
    Eigen::Matrix<double, 9, 1> rv;
    for (int k = 0; k < 9; ++k) {
      rv[k] = r[k].a;
      for (int i = 0; i < n; ++i) jacobian(k, i) = r[k].v[i];
    }
    h->noalias() = jacobian.transpose() * jacobian;
    g->noalias() = jacobian.transpose() * rv;
    double anchors = 0;
    for (int i = 0; i < n; ++i) {
      const double d_ref = x[i] - s_.ref_free[i];
      (*h)(i, i) += w_ref2_;
      (*g)[i] += w_ref2_ * d_ref;
      anchors += w_ref2_ * d_ref * d_ref;
      if (w_prev2_ > 0) {
        const double d_prev = x[i] - s_.prev_free[i];
        (*h)(i, i) += w_prev2_;
        (*g)[i] += w_prev2_ * d_prev;
        anchors += w_prev2_ * d_prev * d_prev;
      }
    }
    return 0.5 * (rv.squaredNorm() + anchors);
  }

  bool SolveDamped(IkMatrix& a, const IkVector& g, IkVector* step) const {
    const Eigen::LLT<IkMatrix> llt(a);
    if (llt.info() != Eigen::Success) return false;
    *step = -llt.solve(g);
    return step->allFinite();
  }

  // The step projected onto the joints' bounds (as Ceres projects a step onto parameter
  // bounds).
  void Plus(const IkVector& x, const IkVector& step, IkVector* candidate) const {
    *candidate = x + step;
    for (int i = 0; i < candidate->size(); ++i) {
      (*candidate)[i] = std::clamp((*candidate)[i], s_.lower[i], s_.upper[i]);
    }
  }

 private:
  const IkProblemSpec& s_;
  double w_ref2_, w_prev2_;
};

// One bounded trust-region solve from x (in place) with the given weights: Levenberg-
// Marquardt with Ceres' rules (util/dense_lm.h), steps projected onto the bounds; the
// active-set loop below handles joints that end on a limit. (Until issue 28 a
// ceres::Problem per solve, DENSE_QR: its set-up cost more than the 2-4 angles' arithmetic.)
void SolveOnce(const IkProblemSpec& s,
               double w_ref,
               double w_prev,
               int max_iterations,
               std::vector<double>* x,
               SolveOutcome* out) {
  const int n = static_cast<int>(s.slots.size());
  ARCO_CHECK(n >= 1 && n <= 4) << "unsupported free dof count " << n;
  IkProblem problem(s, w_ref, w_prev);
  DenseLmOptions options;
  options.max_iterations = max_iterations;
  options.function_tolerance = 1e-14;
  options.gradient_tolerance = 1e-14;
  options.parameter_tolerance = 1e-12;
  options.keep_last_step = false;  // Ceres' stopping point
  IkVector v = Eigen::Map<const IkVector>(x->data(), n);
  DenseLm<IkVector, IkMatrix> solver;
  const DenseLmSummary summary = solver.Minimize(problem, options, &v);
  std::copy(v.data(), v.data() + n, x->begin());
  out->converged = summary.converged;
  out->iterations += summary.steps + 1;  // counted as Ceres did: the start is iteration 0
  out->solves += 1;
  out->termination = summary.converged ? "CONVERGENCE" : "NO_CONVERGENCE";
}

// Gradient of the weighted cost with respect to the free angles: twice the least-squares
// problem's J^T r (IkProblem::Evaluate's g is that of half the cost).
std::vector<double> CostGradient(const IkProblemSpec& s,
                                 double w_ref,
                                 double w_prev,
                                 const std::vector<double>& x) {
  const int n = static_cast<int>(x.size());
  IkMatrix h(n, n);
  IkVector g(n);
  IkProblem(s, w_ref, w_prev).Evaluate(Eigen::Map<const IkVector>(x.data(), n), &h, &g);
  std::vector<double> gradient(x.size());
  for (int i = 0; i < n; ++i) gradient[i] = 2 * g[i];
  return gradient;
}

// Ceres projects trust-region steps onto the bounds, which crawls when a joint
// sits on a limit that the unconstrained step points through. An active-set
// loop fixes those joints (on the limit, gradient pointing outwards) and
// re-solves the rest, until the active set no longer changes.
void SolveActiveSet(const IkProblemSpec& s,
                    double w_ref,
                    double w_prev,
                    int max_iterations,
                    std::vector<double>* x,
                    SolveOutcome* out) {
  SolveOnce(s, w_ref, w_prev, max_iterations, x, out);
  std::vector<bool> previous_active;
  for (int round = 0; round < 4; ++round) {
    const std::vector<double> g = CostGradient(s, w_ref, w_prev, *x);
    std::vector<bool> active(x->size(), false);
    int num_active = 0;
    for (size_t i = 0; i < x->size(); ++i) {
      const double xi = (*x)[i];
      active[i] = (xi <= s.lower[i] + 1e-12 && g[i] > 0) || (xi >= s.upper[i] - 1e-12 && g[i] < 0);
      num_active += active[i];
    }
    if (num_active == 0 || num_active == static_cast<int>(x->size()) || active == previous_active) {
      break;
    }
    previous_active = active;
    IkProblemSpec reduced = s;
    reduced.slots.clear();
    reduced.lower.clear();
    reduced.upper.clear();
    reduced.ref_free.clear();
    reduced.prev_free.clear();
    std::vector<double> xr;
    for (size_t i = 0; i < x->size(); ++i) {
      if (active[i]) {
        reduced.reference[s.slots[i]] = (*x)[i];
        continue;
      }
      reduced.slots.push_back(s.slots[i]);
      reduced.lower.push_back(s.lower[i]);
      reduced.upper.push_back(s.upper[i]);
      reduced.ref_free.push_back(s.ref_free[i]);
      if (s.has_prev) reduced.prev_free.push_back(s.prev_free[i]);
      xr.push_back((*x)[i]);
    }
    SolveOnce(reduced, w_ref, w_prev, max_iterations, &xr, out);
    for (size_t i = 0, j = 0; i < x->size(); ++i) {
      if (!active[i]) (*x)[i] = xr[j++];
    }
  }
}

// from_reference: the first start (regularised solve, then the exact-reach
// polish); restarts from seeds skip the regularised stage, which would drag
// them back towards the reference's basin.
SolveOutcome SolveFrom(const IkProblemSpec& s,
                       const FingerIkOptions& o,
                       std::vector<double> x,
                       bool from_reference) {
  SolveOutcome out;
  if (from_reference || !o.exact_reach) {
    SolveActiveSet(
        s, o.reference_weight_mm_per_rad, o.previous_weight_mm_per_rad, o.max_iterations, &x, &out);
  }
  if (o.exact_reach) {
    SolveActiveSet(s,
                   1e-4 * o.reference_weight_mm_per_rad,
                   1e-4 * o.previous_weight_mm_per_rad,
                   o.max_iterations,
                   &x,
                   &out);
  }
  for (size_t i = 0; i < x.size(); ++i) x[i] = std::clamp(x[i], s.lower[i], s.upper[i]);
  out.x = x;
  out.distance_mm = TipDistance(s, x);
  out.regularisation = KeypointTerms(s, x);
  for (size_t i = 0; i < x.size(); ++i) {
    out.regularisation += std::pow(o.reference_weight_mm_per_rad * (x[i] - s.ref_free[i]), 2);
    if (s.has_prev) {
      out.regularisation += std::pow(o.previous_weight_mm_per_rad * (x[i] - s.prev_free[i]), 2);
    }
  }
  return out;
}

bool Better(const SolveOutcome& a, const SolveOutcome& b, double tol_mm) {
  const double da = a.distance_mm <= tol_mm ? 0.0 : a.distance_mm;
  const double db = b.distance_mm <= tol_mm ? 0.0 : b.distance_mm;
  if (da != db) return da < db;
  return a.regularisation < b.regularisation;
}

}  // namespace

namespace internal {

std::vector<double> RestartGridTipDistances(const HandModel& model,
                                            Finger finger,
                                            const std::array<double, 4>& reference,
                                            const std::vector<int>& slots,
                                            const std::vector<double>& lower,
                                            const std::vector<double>& upper,
                                            int levels,
                                            const Eigen::Matrix3d& world_from_wrist_rotation,
                                            const Eigen::Vector3d& wrist_in_world_mm,
                                            const Eigen::Vector3d& target_in_world_mm) {
  // Per slot its values (the reference alone when fixed) and its step in the point index.
  std::array<std::vector<double>, 4> values;
  std::array<int, 4> stride{};
  for (int slot = 0; slot < 4; ++slot) values[slot] = {reference[slot]};
  int combos = 1;
  for (size_t i = 0; i < slots.size(); ++i) {
    std::vector<double>& v = values[slots[i]];
    v.resize(static_cast<size_t>(levels));
    for (int l = 0; l < levels; ++l) v[l] = lower[i] + (upper[i] - lower[i]) * l / (levels - 1.0);
    stride[slots[i]] = combos;
    combos *= levels;
  }
  const int k0 = KeypointIndex(finger, 0);
  const Eigen::Vector3d out0 = model.rest_offset_mm(k0);
  const Eigen::Vector3d& r1 = model.rest_offset_mm(k0 + 1);
  const Eigen::Vector3d& r2 = model.rest_offset_mm(k0 + 2);
  const Eigen::Vector3d& r3 = model.rest_offset_mm(k0 + 3);
  std::vector<Eigen::Matrix3d> middle, distal;
  for (double a : values[2])
    middle.push_back(AxisRotation<double>(model.axis(DofIndex(finger, FingerDof::kMiddleFlex)), a));
  for (double a : values[3])
    distal.push_back(AxisRotation<double>(model.axis(DofIndex(finger, FingerDof::kDistalFlex)), a));
  std::vector<double> distances(static_cast<size_t>(combos));
  for (size_t l0 = 0; l0 < values[0].size(); ++l0) {
    for (size_t l1 = 0; l1 < values[1].size(); ++l1) {
      const double base_dofs[4] = {values[0][l0], values[1][l1], 0.0, 0.0};
      const Eigen::Matrix3d g0 = BaseJointRotation(model, finger, base_dofs);
      const Eigen::Vector3d out1 = out0 + g0 * r1;
      for (size_t l2 = 0; l2 < middle.size(); ++l2) {
        const Eigen::Matrix3d g2 = g0 * middle[l2];
        const Eigen::Vector3d out2 = out1 + g2 * r2;
        for (size_t l3 = 0; l3 < distal.size(); ++l3) {
          const Eigen::Matrix3d g3 = g2 * distal[l3];
          const Eigen::Vector3d out3 = out2 + g3 * r3;
          const size_t c = l0 * stride[0] + l1 * stride[1] + l2 * stride[2] + l3 * stride[3];
          distances[c] =
              (world_from_wrist_rotation * out3 + wrist_in_world_mm - target_in_world_mm).norm();
        }
      }
    }
  }
  return distances;
}

}  // namespace internal

const char* FingerIkJointsName(FingerIkJoints joints) {
  switch (joints) {
    case FingerIkJoints::kPipDip:
      return "pip_dip";
    case FingerIkJoints::kMcpFlexPipDip:
      return "mcp_flex_pip_dip";
    case FingerIkJoints::kAll:
      return "all";
  }
  return "invalid";
}

std::vector<FingerDof> FreeDofs(FingerIkJoints joints) {
  switch (joints) {
    case FingerIkJoints::kPipDip:
      return {FingerDof::kMiddleFlex, FingerDof::kDistalFlex};
    case FingerIkJoints::kMcpFlexPipDip:
      return {FingerDof::kBaseFlex, FingerDof::kMiddleFlex, FingerDof::kDistalFlex};
    case FingerIkJoints::kAll:
      return {FingerDof::kBaseFlex,
              FingerDof::kBaseAbd,
              FingerDof::kMiddleFlex,
              FingerDof::kDistalFlex};
  }
  throw std::invalid_argument("FreeDofs: unknown FingerIkJoints value");
}

Status FingerIkOptions::Validate() const {
  auto bad = [](const std::string& what) { return Status::Error("FingerIkOptions: " + what); };
  if (!(reference_weight_mm_per_rad >= 0) || !std::isfinite(reference_weight_mm_per_rad))
    return bad("reference_weight_mm_per_rad must be finite and >= 0");
  if (!(previous_weight_mm_per_rad >= 0) || !std::isfinite(previous_weight_mm_per_rad))
    return bad("previous_weight_mm_per_rad must be finite and >= 0");
  if (!(max_change_deg > 0)) return bad("max_change_deg must be > 0");
  if (!(pip_weight >= 0) || !std::isfinite(pip_weight))
    return bad("pip_weight must be finite and >= 0");
  if (pip_target_in_world_mm && !pip_target_in_world_mm->allFinite())
    return bad("pip_target_in_world_mm must be finite");
  if (!(dip_weight >= 0) || !std::isfinite(dip_weight))
    return bad("dip_weight must be finite and >= 0");
  if (dip_target_in_world_mm && !dip_target_in_world_mm->allFinite())
    return bad("dip_target_in_world_mm must be finite");
  if (seed_levels < 0 || seed_levels == 1 || seed_levels > 32) {
    return bad("seed_levels must be 0 (auto) or in [2, 32]");
  }
  if (restarts < 0) return bad("restarts must be >= 0");
  if (!(reach_tolerance_mm > 0)) return bad("reach_tolerance_mm must be > 0");
  if (max_iterations < 1) return bad("max_iterations must be >= 1");
  if (previous_pose && previous_weight_mm_per_rad > 0) {
    for (double a : previous_pose->angles_rad) {
      if (!std::isfinite(a)) return bad("previous_pose has a non-finite angle");
    }
  }
  return Status::Ok();
}

FingerIkResult SolveFingertipIk(const HandModel& model,
                                const HandPose& reference,
                                Finger finger,
                                const Eigen::Vector3d& target_in_world_mm,
                                const FingerIkOptions& options) {
  const Status valid = options.Validate();
  if (!valid.ok()) throw std::invalid_argument(valid.message());
  const int f = static_cast<int>(finger);
  if (f < 0 || f >= kNumFingers) throw std::invalid_argument("SolveFingertipIk: bad finger");

  FingerIkResult result;
  result.pose = ClampToLimits(model, reference);
  for (int d = 0; d < kNumJointDofs; ++d) {
    if (!(reference.angles_rad[d] == result.pose.angles_rad[d])) ++result.clamped_reference_dofs;
  }
  if (!target_in_world_mm.allFinite() || !reference.world_from_wrist.rotation.allFinite() ||
      !reference.world_from_wrist.translation.allFinite()) {
    result.status =
        Status::Error(std::string("fingertip IK: non-finite ") +
                      (target_in_world_mm.allFinite() ? "reference wrist pose" : "target"));
    result.initial_distance_mm = result.final_distance_mm = std::nan("");
    result.termination = "not run";
    return result;
  }

  IkProblemSpec s;
  s.model = &model;
  s.finger = finger;
  for (int i = 0; i < 4; ++i) s.reference[i] = result.pose.angles_rad[4 * f + i];
  s.rotation = reference.world_from_wrist.rotation;
  s.translation = reference.world_from_wrist.translation;
  s.target = target_in_world_mm;
  if (options.pip_target_in_world_mm && options.pip_weight > 0) {
    s.pip_weight = options.pip_weight;
    s.pip_target = *options.pip_target_in_world_mm;
  }
  if (options.dip_target_in_world_mm && options.dip_weight > 0) {
    s.dip_weight = options.dip_weight;
    s.dip_target = *options.dip_target_in_world_mm;
  }
  s.has_prev = options.previous_pose.has_value() && options.previous_weight_mm_per_rad > 0;
  const double max_change_rad = options.max_change_deg * kDegToRad;
  for (FingerDof slot : FreeDofs(options.joints)) {
    const int i = static_cast<int>(slot);
    const int dof = 4 * f + i;
    const double lower = std::max(model.min_rad(dof), s.reference[i] - max_change_rad);
    const double upper = std::min(model.max_rad(dof), s.reference[i] + max_change_rad);
    if (!(upper - lower > 1e-12)) continue;  // a locked joint (min == max) stays fixed
    s.slots.push_back(i);
    s.lower.push_back(lower);
    s.upper.push_back(upper);
    s.ref_free.push_back(s.reference[i]);
    if (s.has_prev) {
      s.prev_free.push_back(
          std::clamp(options.previous_pose->angles_rad[dof], s.lower.back(), s.upper.back()));
    }
  }
  result.initial_distance_mm = TipDistance(s, s.ref_free);
  if (s.slots.empty()) {
    result.final_distance_mm = result.initial_distance_mm;
    result.converged = true;
    result.termination = "no free joint";
    return result;
  }

  SolveOutcome best = SolveFrom(s, options, s.ref_free, /*from_reference=*/true);
  int iterations = best.iterations, solves = best.solves;
  if (best.distance_mm > options.reach_tolerance_mm && options.restarts > 0) {
    // The reach cost has genuine local minima on the limits (corners of the
    // box, targets behind the finger), so restart from the best points of a
    // deterministic grid over the bounds (corners included).
    const int n = static_cast<int>(s.slots.size());
    const int levels = options.seed_levels > 0 ? options.seed_levels : kAutoSeedLevels[n];
    int combos = 1;
    for (int i = 0; i < n; ++i) combos *= levels;
    std::vector<std::pair<double, int>> scored(combos);
    std::vector<double> seed(n);
    auto decode = [&](int c) {
      for (int i = 0; i < n; ++i, c /= levels) {
        seed[i] = s.lower[i] + (s.upper[i] - s.lower[i]) * (c % levels) / (levels - 1.0);
      }
    };
    const std::vector<double> distances = internal::RestartGridTipDistances(model,
                                                                            finger,
                                                                            s.reference,
                                                                            s.slots,
                                                                            s.lower,
                                                                            s.upper,
                                                                            levels,
                                                                            s.rotation,
                                                                            s.translation,
                                                                            s.target);
    for (int c = 0; c < combos; ++c) scored[c] = {distances[c], c};
    const int keep = std::min(options.restarts, combos);
    std::partial_sort(scored.begin(), scored.begin() + keep, scored.end());
    for (int r = 0; r < keep; ++r) {
      decode(scored[r].second);
      SolveOutcome candidate = SolveFrom(s, options, seed, /*from_reference=*/false);
      iterations += candidate.iterations;
      solves += candidate.solves;
      if (Better(candidate, best, options.reach_tolerance_mm)) best = candidate;
    }
  }

  for (size_t i = 0; i < s.slots.size(); ++i) {
    const int dof = 4 * f + s.slots[i];
    result.pose.angles_rad[dof] = best.x[i];
    if (best.x[i] <= model.min_rad(dof) + kActiveTolRad ||
        best.x[i] >= model.max_rad(dof) - kActiveTolRad) {
      result.active_limit_dofs.push_back(dof);
    } else if (best.x[i] <= s.lower[i] + kActiveTolRad || best.x[i] >= s.upper[i] - kActiveTolRad) {
      result.step_limited = true;
    }
  }
  ARCO_CHECK(CountLimitViolations(model, result.pose) == 0) << "IK produced a limit violation";
  result.converged = best.converged;
  result.iterations = iterations;
  result.solves = solves;
  result.final_distance_mm = best.distance_mm;
  result.termination = best.termination;
  return result;
}

}  // namespace arco::hand
