// The instrument's rigid SPD keypoints at their nominal places in the instrument frame:
// what a pose from one view (PnP) is solved against before a capture's own template
// exists (template_fit.h), and what arco synth places on its instruments.
//
// Instrument frame (strings.h): origin at the bridge centre, x from the bridge towards the
// nut, z the top-plate normal pointing to the front, y = z x x towards the LOW-string
// side. Millimetres. nut_l/r and bridge_l/r are the outer strings at the model's string
// length and spacings; the offsets the model does not give (scroll, tail gut, end pin)
// come from the real SPD frame-128 labels of a cello (DOMAIN.md section 5: scroll_top
// 186 mm beyond the nut, tail_gut 377 mm below the bridge, end_pin 314 mm beyond the tail
// gut), scaled by string length for the other instruments.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "arco/instrument/instrument_model.h"

namespace arco {

// String length of the cello the offsets were measured on (mm).
inline constexpr double kNominalReferenceCelloMm = 695.0;

// model.keypoint_names() order; NaN for the bow's frog and tip (they move with the bow).
std::vector<Eigen::Vector3d> NominalKeypointsInInstrument(const InstrumentModel& model);

}  // namespace arco
