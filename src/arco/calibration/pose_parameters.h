// The parameter scaffold both calibration bundle adjustments share (the board rig's,
// rig_calibration.h, and the refine from the performer's, bundle_adjustment.h): a rigid
// pose as 6 parameters, an angle-axis rotation then a translation (the order
// reprojection_cost.h's residuals read), and the RMS their reports give. Written once so
// that both adjustments start from, and read back, exactly the same numbers.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "arco/geometry/transform.h"

namespace arco::calibration {

inline constexpr int kPoseParams = 6;

// params[0..2] = angle-axis of R, params[3..5] = t.
void PoseToParams(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, double* params);
void ParamsToPose(const double* params, Eigen::Matrix3d* R, Eigen::Vector3d* t);
// The same for a whole pose: its 6 parameters, and the pose from them.
std::array<double, kPoseParams> ParamsFromRigid(const RigidMatrix3d& pose);
RigidMatrix3d RigidFromParams(const double* params);

// Root mean square of the values; 0 for none (a camera with no observations left).
double Rms(const std::vector<double>& values);

}  // namespace arco::calibration
