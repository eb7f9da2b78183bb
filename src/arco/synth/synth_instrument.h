// What the synthesiser adds to an instrument model: the score range and GM
// program, the SPD keypoints as a rigid template in the instrument frame, the
// body outline used for occlusion, and the instrument's strings.
//
// Instrument frame (instrument/strings.h): origin at the bridge centre, x from the
// bridge towards the nut, z the top-plate normal pointing to the front (away from
// the performer), y = z x x towards the LOW-string side. Millimetres.
//
// The keypoints are instrument/nominal_keypoints.h's (what `arco calibrate
// from-instrument` solves PnP against); the body outline's offsets, like theirs, come
// from the real SPD frame-128 labels of a cello (DOMAIN.md section 5), scaled by string
// length for the other instruments.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "arco/instrument/instrument_model.h"
#include "arco/instrument/strings.h"
#include "arco/synth/score.h"
#include "arco/util/status.h"

namespace arco::synth {

// Score range from the model: open strings (rounded to MIDI), semitones of range.
ScoreInstrument ScoreInstrumentFor(const InstrumentModel& model);

// General MIDI program (0-based): violin 40, viola 41, cello 42, double bass 43.
int GmProgramFor(InstrumentKind kind);

struct InstrumentTemplate {
  // Rigid keypoints in the instrument frame, in model.keypoint_names() order; the
  // bow's frog and tip are NaN here (they move with the bow).
  std::vector<Eigen::Vector3d> keypoints_mm;
  // Strings (index = string - 1, 1 = highest) in the instrument frame.
  std::vector<StringSegment> strings_mm;
  // Body outline for occlusion: an ellipse in the plane z = body_plane_z_mm,
  // centred at (body_center_x_mm, 0), semi-axes along x and y.
  double body_center_x_mm = 0;
  double body_half_length_mm = 0;
  double body_half_width_mm = 0;
  double body_plane_z_mm = 0;
  double neck_depth_mm = 0;  // string plane to the back of the neck (thumb side)
  double scale = 1;          // string length / 695 mm (the cello the offsets come from)
};

// Builds the template; the strings come from the instrument layer's
// GeometryFromEdges on the template's own nut/bridge edge points.
StatusOr<InstrumentTemplate> MakeInstrumentTemplate(const InstrumentModel& model);

// Point where a finger stops `string` (1 = highest) for f0_hz, in the instrument
// frame (ideal string, instrument/contact.h); NaN when f0 is not a stopped note.
Eigen::Vector3d ContactInInstrument(const InstrumentModel& model,
                                    const InstrumentTemplate& tmpl,
                                    int string,
                                    double f0_hz);

}  // namespace arco::synth
