// The one way the calibration bundle adjustments (rig_calibration.cc's board rig,
// bundle_adjustment.cc's refine) run Ceres: Schur elimination in the caller's ordering,
// tight tolerances, one thread. Include only from code that links Ceres.
#pragma once

#include <ceres/ceres.h>

#include <chrono>
#include <memory>

#include "arco/calibration/bundle_adjustment.h"
#include "arco/util/status.h"

namespace arco::calibration {

// Solves `problem`; time_s counts from `start`. Errors: Ceres's FAILURE (with its message).
StatusOr<BundleAdjustmentSummary> SolveBundle(
    ceres::Problem* problem,
    std::shared_ptr<ceres::ParameterBlockOrdering> ordering,
    int max_iterations,
    std::chrono::steady_clock::time_point start);

}  // namespace arco::calibration
