// The instrument's rigid SPD keypoints at their nominal places in the instrument frame:
// what a pose from one view (PnP) is solved against before a capture's own template
// exists (template_fit.h), and what arco synth places on its instruments.
//
// Instrument frame (strings.h): origin at the bridge centre, x from the bridge towards the
// nut, z the top-plate normal pointing to the front, y = z x x towards the LOW-string
// side. Millimetres. nut_l/r and bridge_l/r are the outer strings at the model's string
// length and spacings; the places the model does not give (scroll, tail gut, end pin)
// are those of a real cello, triangulated from SPD's frame-128 labels in four views
// (../shared/data/spd/labels_frame128; instrument_real_test.cc measures them): scroll_top
// 185 mm beyond the nut and 30 mm behind the strings' plane, the tail gut 342 mm below
// the bridge and 158 mm behind the strings (the bridge lifts them 90 mm off the top, the
// top arches down to the saddle), the end pin's floor point 637 mm below the bridge and
// 284 mm behind them; on the centre line (y = 0: the labels put the tail gut 12 mm and
// the end pin 33 mm to one side, a lean of the one cello, not its design). Scaled by
// string length for the other instruments. (Before, only the distances were taken from
// those labels and the heights guessed, 75 and 120 mm: one view's PnP then rejected both
// points as outliers on 95 of the real take's 330 frames and went without a pose.)
#pragma once

#include <Eigen/Core>
#include <vector>

#include "arco/instrument/instrument_model.h"

namespace arco {

// String length of the cello the offsets were measured on (mm).
inline constexpr double kNominalReferenceCelloMm = 695.0;

// model.keypoint_names() order; NaN for the bow's frog and tip (they move with the bow).
std::vector<Eigen::Vector3d> NominalKeypointsInInstrument(const InstrumentModel& model);

// The points a pose is solved against when the capture has no template of its own (one
// view's PnP, a camera posed from the instrument): NominalKeypointsInInstrument without the
// end pin, NaN there. The end pin's spike is pulled out as far as its player wants, so
// where it meets the floor is the player's, not the instrument's; a capture's own template
// measures it (template_fit.h). On the real take seen by one camera, dropping it from the
// PnP took the finger agreement from 0.855 to 0.862 and the strings from 0.970 to 0.977
// (docs/accuracy.md, "One camera: the instrument's real shape").
std::vector<Eigen::Vector3d> NominalPoseKeypointsInInstrument(const InstrumentModel& model);

// The points a pose is solved against when the capture has no template of its own (one
// view's PnP, a camera posed from the instrument): NominalKeypointsInInstrument without the
// end pin, NaN there. The end pin's spike is pulled out as far as its player wants, so
// where it meets the floor is the player's, not the instrument's; a capture's own template
// measures it (template_fit.h). On the real take seen by one camera, dropping it from the
// PnP took the finger agreement from 0.855 to 0.862 and the strings from 0.970 to 0.977
// (docs/accuracy.md, "One camera: the instrument's real shape").
std::vector<Eigen::Vector3d> NominalPoseKeypointsInInstrument(const InstrumentModel& model);

}  // namespace arco
