// Strings in 3D and the instrument coordinate frame.
//
// Instrument frame (millimetres):
//   origin  the bridge centre (midpoint of the two bridge edge points),
//   x       along the strings from the bridge toward the nut centre,
//   z       the top-plate normal, pointing to the FRONT (away from the performer),
//   y = z x x, which points to the LOW-string side: seen from the front with the scroll up
//           the lowest string is on the viewer's left (DOMAIN.md section 5), and a viewer
//           looking along -z with x up has +y on the left.
// World points are in the calibration's units (arbitrary for Metashape rigs, hence
// world_from_instrument.scale, below).
//
// String order comes from geometry, never from label names: the two edge points at each
// end (SPD nut_l/nut_r, bridge_l/bridge_r) span the string plane with the string axis;
// the plane normal's sign comes from a FrontHint (which side the performer is on); the
// edge point on the +y side carries the lowest string. The labels' own l/r claim is only
// reported (StringOrderReport::labels_agree).
//
// Spacing: the SPD authors place four strings at fractions 0, 1/3, 2/3, 1 between the
// labelled edge lines. arco places the strings at the instrument's real outer-string
// spacing (InstrumentModel::nut_spacing_mm / bridge_spacing_mm) centred on the midpoint of
// each labelled edge and along its direction, so the strings keep their true positions
// whether the labeller clicked the outer strings or the fingerboard edges.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "arco/geometry/transform.h"
#include "arco/instrument/instrument_model.h"
#include "arco/util/status.h"

namespace arco {

// The instrument's pose is geometry's SimMatrix3d `world_from_instrument`:
// point_in_world = scale * (rotation * point_in_instrument_mm) + translation, its scale
// the world units per mm; rotation's columns are the instrument x, y, z axes in the
// world; translation is the bridge centre in world units. A matrix rotation, not Sim3d's
// quaternion: the instrument's numbers are matrix products (docs/architecture.md).

// One string from the nut to the bridge (in whichever frame its container says).
struct StringSegment {
  int string = 0;  // 1 = highest
  Eigen::Vector3d nut = Eigen::Vector3d::Zero();
  Eigen::Vector3d bridge = Eigen::Vector3d::Zero();

  // 0 = bridge, 1 = nut; use Contact::fraction_from_bridge (contact.h).
  Eigen::Vector3d PointAtFraction(double fraction_from_bridge) const {
    return bridge + fraction_from_bridge * (nut - bridge);
  }
};

// Which way is the front of the instrument. The performer sits behind the instrument's
// back, so a point on the performer's torso (shoulder midpoint, left shoulder, neck) lies
// on the back side of the top plate; a frontal camera's centre (or the mean centre of the
// cameras facing the player) lies on the front side.
struct FrontHint {
  enum class Kind {
    kPerformerPoint,  // `value` is a point in the world on the performer's side (behind)
    kFrontPoint,      // `value` is a point in the world in front of the top plate
    kFrontDirection,  // `value` is a world direction pointing out of the top plate
  };
  Kind kind = Kind::kPerformerPoint;
  Eigen::Vector3d value = Eigen::Vector3d::Zero();
};

struct StringGeometryOptions {
  enum class Spacing {
    kInstrument,         // the instrument's real spacing (default, see header comment)
    kEvenBetweenLabels,  // the SPD authors' even fractions between the labelled edges
  };
  Spacing spacing = Spacing::kInstrument;
  // A hint point nearer than this to the top-plate plane (or a direction within
  // min_front_angle_deg of the plane) makes the order ambiguous.
  double min_front_margin_mm = 30.0;
  double min_front_angle_deg = 10.0;
  // The nut and bridge edges, projected across the strings, should be nearly parallel
  // (they span the string plane); beyond this angle the plane is ambiguous.
  double max_edge_angle_deg = 35.0;
  // World units per mm; 0 = from the nut-bridge distance and the model's string length.
  double world_units_per_mm = 0.0;

  Status Validate() const;
};

struct StringOrderReport {
  bool ambiguous = false;
  std::string warning;         // empty unless ambiguous or noteworthy
  bool labels_agree = true;    // nut_l and bridge_l are on the low-string side, as SPD intends
  double front_margin_mm = 0;  // hint distance from the top-plate plane (degrees for a
                               // direction hint: angle out of the plane)
};

// Edge points of the strings at nut and bridge, in SPD label naming (which may be wrong).
struct StringEdges {
  Eigen::Vector3d nut_l, nut_r, bridge_l, bridge_r;
};

struct InstrumentGeometry {
  SimMatrix3d world_from_instrument;   // see above; scale = world units per mm
  std::vector<StringSegment> strings;  // in the world; index = string - 1
  StringOrderReport order;
  // The same strings in the instrument frame (mm).
  std::vector<StringSegment> strings_in_instrument;
};

// Builds the instrument frame and the strings from the four edge points (one frame, or a
// fitted template). Errors (Status): non-finite points, nut and bridge coincident, both
// edges of zero width or along the strings (no string plane), a non-finite hint.
StatusOr<InstrumentGeometry> GeometryFromEdges(const InstrumentModel& model,
                                               const StringEdges& edges_in_world,
                                               const FrontHint& hint,
                                               const StringGeometryOptions& options = {});

// The strings of `strings_in_instrument` placed in the world (index = string - 1).
std::vector<StringSegment> StringsInWorld(const std::vector<StringSegment>& strings_in_instrument,
                                          const SimMatrix3d& world_from_instrument);

}  // namespace arco
