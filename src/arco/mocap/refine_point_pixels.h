// Internal to mocap/ (refine_point.cc and triangulate_point.cc): RefinePointRobust that
// also hands back each view's distorted pixel at the point it returns. The refinement's
// last accepted pass over the views already projected the point into every view it
// refines (Camera::ProjectWithJacobian, the same bits as Camera::Project), so the
// triangulation's final classification need not project those views again (it took an
// eighth of the triangulation stage's CPU, docs/performance.md, issue 28 part 3).
#pragma once

#include <Eigen/Core>

#include "arco/mocap/refine_point.h"

namespace arco::internal {

// As RefinePointRobust. `pixels` holds 2 * count entries of scratch; when true is
// returned, pixels[i] for i < count is view i's pixel at the returned point. False when
// the start is behind a view (the point is then returned unchanged, as
// RefinePointRobust does, and no pixel is known).
bool RefinePointRobustWithPixels(const RefinementView* views,
                                 int count,
                                 const PointRefinementOptions& options,
                                 Eigen::Vector3d* point_in_world,
                                 Eigen::Vector2d* pixels,
                                 PointRefinementSummary* summary);

}  // namespace arco::internal
