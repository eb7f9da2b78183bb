#include "arco/synth/synth_instrument.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "arco/instrument/contact.h"
#include "arco/instrument/nominal_keypoints.h"

namespace arco::synth {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

ScoreInstrument ScoreInstrumentFor(const InstrumentModel& model) {
  ScoreInstrument s;
  s.name = model.name();
  const int n = model.num_strings();
  int semis = 1000;
  for (int string = n; string >= 1; --string) {  // lowest first
    const double open = model.open_hz(string);
    s.open_string_midi.push_back(static_cast<int>(std::lround(69 + 12 * std::log2(open / 440.0))));
    semis = std::min(
        semis, static_cast<int>(std::floor(12 * std::log2(model.max_hz(string) / open) + 1e-6)));
  }
  s.max_semitones_above_open = semis;
  s.gm_program = GmProgramFor(model.kind());
  s.hand_span_semitones = 0;
  for (const FingerSpan& span : GetInstrumentInfo(model.kind()).hand_frame) {
    if (!span.extended)
      s.hand_span_semitones = std::max(s.hand_span_semitones, span.offset_semitones);
  }
  return s;
}

int GmProgramFor(InstrumentKind kind) { return GetInstrumentInfo(kind).gm_program; }

StatusOr<InstrumentTemplate> MakeInstrumentTemplate(const InstrumentModel& model) {
  InstrumentTemplate t;
  const double length = model.string_length_mm();
  t.scale = length / kNominalReferenceCelloMm;
  const double s = t.scale;
  // Edge points at the real outer-string spacing; the low string on +y.
  StringEdges edges;
  edges.nut_l = Eigen::Vector3d(length, 0.5 * model.nut_spacing_mm(), 0);
  edges.nut_r = Eigen::Vector3d(length, -0.5 * model.nut_spacing_mm(), 0);
  edges.bridge_l = Eigen::Vector3d(0, 0.5 * model.bridge_spacing_mm(), 0);
  edges.bridge_r = Eigen::Vector3d(0, -0.5 * model.bridge_spacing_mm(), 0);
  FrontHint hint;
  hint.kind = FrontHint::Kind::kFrontDirection;
  hint.value = Eigen::Vector3d::UnitZ();
  StringGeometryOptions options;
  options.world_units_per_mm = 1.0;
  auto geometry = GeometryFromEdges(model, edges, hint, options);
  if (!geometry.ok()) return geometry.status().WithContext("instrument template");
  t.strings_mm = geometry->strings;
  t.keypoints_mm = NominalKeypointsInInstrument(model);
  // The body: about 755 mm long on a cello, its lower end near the tail gut; the
  // top plate about 90 mm (bridge height) below the strings at the bridge.
  t.body_half_length_mm = 0.5 * 755 * s;
  t.body_center_x_mm = -377 * s + t.body_half_length_mm;
  t.body_half_width_mm = 215 * s;
  t.body_plane_z_mm = -90 * s;
  t.neck_depth_mm = 45 * s;
  return t;
}

Eigen::Vector3d ContactInInstrument(const InstrumentModel& model,
                                    const InstrumentTemplate& tmpl,
                                    int string,
                                    double f0_hz) {
  const Contact c = ContactPoint(model, string, f0_hz);
  if (!c.stopped()) return Eigen::Vector3d::Constant(kNaN);
  return tmpl.strings_mm[static_cast<size_t>(string - 1)].PointAtFraction(c.fraction_from_bridge);
}

}  // namespace arco::synth
