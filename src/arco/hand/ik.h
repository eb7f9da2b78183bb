// Inverse kinematics: "put this fingertip at this point" with a chosen set of
// free joints, joint limits as hard bounds (a Levenberg-Marquardt trust region with Ceres'
// rules, util/dense_lm.h, steps projected onto the bounds), and regularisation towards a reference
// pose (and optionally the previous frame's pose). This is the audio-guided correction's solver
// (the paper's Eq. 3 adjusts PIP and DIP of the note-playing finger: kPipDip).
//
// Cost over the free angles x (rad) of one finger:
//   |tip(x) - target|^2 + w_pip^2 |pip(x) - pip_target|^2 + w_dip^2 |dip(x) - dip_target|^2
//     + w_ref^2 |x - x_ref|^2 + w_prev^2 |x - x_prev|^2
// (the PIP term only with a pip_target: where the PIP keypoint is seen, in position space,
// so the MCP's angles explain the tip's residual only as far as the PIP allows; the DIP
// term likewise with a dip_target: the PIP's flexion only as far as the DIP allows).
// subject to  max(min_k, x_ref,k - max_change) <= x_k <= min(max_k, x_ref,k + max_change).
// With exact_reach, a second solve with the weights scaled by 1e-4 starts from
// the first: the regularisation picks the solution (redundant dofs, unreachable
// targets) and reachable targets are then met to ~1e-6 mm.
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "arco/hand/hand_model.h"
#include "arco/util/status.h"

namespace arco::hand {

enum class FingerIkJoints {
  kPipDip,         // PIP + DIP flexion (thumb: MCP + IP), the paper's mode
  kMcpFlexPipDip,  // + MCP flexion (thumb: + CMC flexion)
  kAll,            // MCP flexion + abduction + PIP + DIP (thumb: CMC 2 axes + MCP + IP)
};
const char* FingerIkJointsName(FingerIkJoints joints);

struct FingerIkOptions {
  FingerIkJoints joints = FingerIkJoints::kPipDip;
  double reference_weight_mm_per_rad = 1.0;  // pull towards the reference angles
  // Optional temporal regularisation towards the previous frame's angles.
  std::optional<HandPose> previous_pose;
  double previous_weight_mm_per_rad = 0.0;
  // Largest change of any free angle from the reference ("small steps"), deg.
  double max_change_deg = 360.0;
  // Optional observation of the finger's PIP keypoint (world, mm) and its weight relative
  // to the tip's (0 = none). Moves only with the MCP's angles free.
  std::optional<Eigen::Vector3d> pip_target_in_world_mm;
  double pip_weight = 0.0;
  // The same for the DIP keypoint (moves with the MCP's and the PIP's angles).
  std::optional<Eigen::Vector3d> dip_target_in_world_mm;
  double dip_weight = 0.0;
  bool exact_reach = true;  // see the header comment
  // When the tip ends farther than reach_tolerance_mm, evaluate a grid of
  // seed_levels values per free joint over its bounds (0 = automatic: 33, 17, 9
  // or 6 levels for 1-4 free joints) and restart from the `restarts` best grid
  // points (0 = never restart).
  int seed_levels = 0;
  int restarts = 3;
  double reach_tolerance_mm = 1e-3;
  int max_iterations = 100;
  // Invalid values (negative weights, max_change_deg <= 0, ...) -> message.
  Status Validate() const;
};

struct FingerIkResult {
  // Not OK for unusable input (non-finite target or reference wrist); `pose`
  // is then the reference clamped into the limits.
  Status status;
  HandPose pose;                   // reference with the free angles solved; within limits
  bool converged = false;          // the chosen solve converged (not out of iterations)
  int iterations = 0;              // all trust-region iterations, all solves
  int solves = 0;                  // 1 or 2 per start, more with restarts
  double initial_distance_mm = 0;  // from the (clamped) reference
  double final_distance_mm = 0;
  std::vector<int> active_limit_dofs;  // dofs (DofIndex) at an anatomical limit
  bool step_limited = false;           // a free dof ended on the max_change box
  int clamped_reference_dofs = 0;      // reference angles that were outside limits
  std::string termination;             // CONVERGENCE or NO_CONVERGENCE (Ceres' words)
};

// Throws std::invalid_argument on invalid options.
FingerIkResult SolveFingertipIk(const HandModel& model,
                                const HandPose& reference,
                                Finger finger,
                                const Eigen::Vector3d& target_in_world_mm,
                                const FingerIkOptions& options);

// Slots (FingerDof) freed by a joints choice.
std::vector<FingerDof> FreeDofs(FingerIkJoints joints);

namespace internal {

// The restart grid's scores: the fingertip's distance (mm) from target_in_world_mm at every
// point of a grid of `levels` values per free slot (slots[i], value lower[i] + (upper[i] -
// lower[i]) l / (levels - 1)), the other slots at `reference`; point c = sum_i l_i levels^i.
// Each joint's rotation per level is made once and the kinematic chain's prefixes are
// shared, in FingerPointsInWrist's arithmetic: the same bits as evaluating each point.
std::vector<double> RestartGridTipDistances(const HandModel& model,
                                            Finger finger,
                                            const std::array<double, 4>& reference,
                                            const std::vector<int>& slots,
                                            const std::vector<double>& lower,
                                            const std::vector<double>& upper,
                                            int levels,
                                            const Eigen::Matrix3d& world_from_wrist_rotation,
                                            const Eigen::Vector3d& wrist_in_world_mm,
                                            const Eigen::Vector3d& target_in_world_mm);

}  // namespace internal

}  // namespace arco::hand
