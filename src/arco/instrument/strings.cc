#include "arco/instrument/strings.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace arco {
namespace {

constexpr double kPi = 3.14159265358979323846;

bool AllFinite(const Eigen::Vector3d& v) { return v.allFinite(); }

std::string Fixed(double v, int digits = 1) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

void AppendWarning(StringOrderReport* report, const std::string& text) {
  if (!report->warning.empty()) report->warning += "; ";
  report->warning += text;
}

}  // namespace

Status StringGeometryOptions::Validate() const {
  if (!std::isfinite(min_front_margin_mm) || min_front_margin_mm < 0) {
    return Status::Error("string geometry: min_front_margin_mm must be >= 0");
  }
  if (!(min_front_angle_deg >= 0 && min_front_angle_deg < 90)) {
    return Status::Error("string geometry: min_front_angle_deg must be in [0, 90)");
  }
  if (!(max_edge_angle_deg > 0 && max_edge_angle_deg <= 90)) {
    return Status::Error("string geometry: max_edge_angle_deg must be in (0, 90]");
  }
  if (!std::isfinite(world_units_per_mm) || world_units_per_mm < 0) {
    return Status::Error(
        "string geometry: world_units_per_mm must be >= 0 (0 = from the "
        "string length)");
  }
  return Status::Ok();
}

StatusOr<InstrumentGeometry> GeometryFromEdges(const InstrumentModel& model,
                                               const StringEdges& e,
                                               const FrontHint& hint,
                                               const StringGeometryOptions& options) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  if (!AllFinite(e.nut_l) || !AllFinite(e.nut_r) || !AllFinite(e.bridge_l) ||
      !AllFinite(e.bridge_r)) {
    return Status::Error("nut/bridge edge points are not finite");
  }
  if (!hint.value.allFinite()) return Status::Error("front hint is not finite");
  const Eigen::Vector3d nut_c = 0.5 * (e.nut_l + e.nut_r);
  const Eigen::Vector3d bridge_c = 0.5 * (e.bridge_l + e.bridge_r);
  const Eigen::Vector3d axis = nut_c - bridge_c;
  const double length_world = axis.norm();
  // Coincidence relative to the size of the coordinates (units are arbitrary).
  const double coord_scale = std::max({1e-300,
                                       nut_c.cwiseAbs().maxCoeff(),
                                       bridge_c.cwiseAbs().maxCoeff(),
                                       (e.nut_r - e.nut_l).norm(),
                                       (e.bridge_r - e.bridge_l).norm()});
  if (!(length_world > 1e-9 * coord_scale)) {
    return Status::Error("nut and bridge coincide: no string direction");
  }
  const Eigen::Vector3d x = axis / length_world;
  const double units_per_mm = options.world_units_per_mm > 0
                                  ? options.world_units_per_mm
                                  : length_world / model.string_length_mm();

  // Edge directions across the strings (projected orthogonal to x).
  auto across = [&](const Eigen::Vector3d& d) -> Eigen::Vector3d { return d - d.dot(x) * x; };
  Eigen::Vector3d e_nut = across(e.nut_r - e.nut_l);
  Eigen::Vector3d e_bridge = across(e.bridge_r - e.bridge_l);
  const double min_width = 1e-6 * length_world;
  const bool nut_ok = e_nut.norm() > min_width;
  const bool bridge_ok = e_bridge.norm() > min_width;
  if (!nut_ok && !bridge_ok) {
    return Status::Error(
        "nut and bridge edges have no width across the strings: no string "
        "plane");
  }
  InstrumentGeometry g;
  StringOrderReport& report = g.order;
  if (!nut_ok) AppendWarning(&report, "nut edge points coincide; plane from the bridge edge");
  if (!bridge_ok) AppendWarning(&report, "bridge edge points coincide; plane from the nut edge");
  bool ends_disagree = false;
  if (nut_ok && bridge_ok && e_nut.dot(e_bridge) < 0) {
    // The l/r labels are swapped at one end; the plane does not care.
    e_nut = -e_nut;
    ends_disagree = true;
  }
  Eigen::Vector3d lateral = Eigen::Vector3d::Zero();
  if (nut_ok) lateral += e_nut.normalized();
  if (bridge_ok) lateral += e_bridge.normalized();
  lateral.normalize();
  if (nut_ok && bridge_ok) {
    const double cos_angle = e_nut.normalized().dot(e_bridge.normalized());
    const double angle_deg = std::acos(std::clamp(cos_angle, -1.0, 1.0)) * 180.0 / kPi;
    if (angle_deg > options.max_edge_angle_deg) {
      report.ambiguous = true;
      AppendWarning(
          &report,
          "nut and bridge edges differ by " + Fixed(angle_deg) + " deg: string plane ill-defined");
    }
  }
  const Eigen::Vector3d z0 = x.cross(lateral).normalized();

  // Sign of the front normal from the hint.
  const Eigen::Vector3d mid = 0.5 * (nut_c + bridge_c);
  double signed_front = 0;  // > 0: z0 points to the front
  if (hint.kind == FrontHint::Kind::kFrontDirection) {
    const double norm = hint.value.norm();
    if (!(norm > 0)) return Status::Error("front hint direction is zero");
    const double s = z0.dot(hint.value / norm);
    signed_front = s;
    report.front_margin_mm = std::asin(std::min(1.0, std::abs(s))) * 180.0 / kPi;
    if (report.front_margin_mm < options.min_front_angle_deg) {
      report.ambiguous = true;
      AppendWarning(&report,
                    "front direction only " + Fixed(report.front_margin_mm) +
                        " deg out of the top-plate plane: string order ambiguous");
    }
  } else {
    const double s = z0.dot(hint.value - mid) / units_per_mm;
    signed_front = hint.kind == FrontHint::Kind::kFrontPoint ? s : -s;
    report.front_margin_mm = std::abs(s);
    if (report.front_margin_mm < options.min_front_margin_mm) {
      report.ambiguous = true;
      AppendWarning(&report,
                    "front hint only " + Fixed(report.front_margin_mm) +
                        " mm from the top-plate plane: string order ambiguous");
    }
  }
  const Eigen::Vector3d z = signed_front >= 0 ? z0 : Eigen::Vector3d(-z0);
  const Eigen::Vector3d y = z.cross(x);

  // Low-string side = +y. Decide per end from geometry.
  const bool nut_l_low = (e.nut_l - e.nut_r).dot(y) > 0;
  const bool bridge_l_low = (e.bridge_l - e.bridge_r).dot(y) > 0;
  const Eigen::Vector3d& nut_low = nut_l_low ? e.nut_l : e.nut_r;
  const Eigen::Vector3d& nut_high = nut_l_low ? e.nut_r : e.nut_l;
  const Eigen::Vector3d& bridge_low = bridge_l_low ? e.bridge_l : e.bridge_r;
  const Eigen::Vector3d& bridge_high = bridge_l_low ? e.bridge_r : e.bridge_l;
  report.labels_agree = (!nut_ok || nut_l_low) && (!bridge_ok || bridge_l_low);
  if (ends_disagree) {
    AppendWarning(&report, "the l/r labels of the nut and the bridge point opposite ways");
  } else if (!report.labels_agree) {
    AppendWarning(&report, "geometry puts the lowest string on the labels' r side");
  }

  g.world_from_instrument.rotation.col(0) = x;
  g.world_from_instrument.rotation.col(1) = y;
  g.world_from_instrument.rotation.col(2) = z;
  g.world_from_instrument.translation = bridge_c;
  g.world_from_instrument.scale = units_per_mm;

  // Unit vectors from the high to the low side along each labelled edge; a degenerate
  // edge borrows the in-plane lateral direction.
  const Eigen::Vector3d y_world = y;
  auto edge_dir = [&](const Eigen::Vector3d& low, const Eigen::Vector3d& high, bool ok) {
    return ok ? Eigen::Vector3d((low - high).normalized()) : y_world;
  };
  const Eigen::Vector3d u_nut = edge_dir(nut_low, nut_high, nut_ok);
  const Eigen::Vector3d u_bridge = edge_dir(bridge_low, bridge_high, bridge_ok);
  const int n = model.num_strings();
  g.strings.resize(n);
  for (int s = 1; s <= n; ++s) {
    StringSegment& seg = g.strings[s - 1];
    seg.string = s;
    if (options.spacing == StringGeometryOptions::Spacing::kInstrument) {
      seg.nut = nut_c + u_nut * (model.LateralOffsetAtNutMm(s) * units_per_mm);
      seg.bridge = bridge_c + u_bridge * (model.LateralOffsetAtBridgeMm(s) * units_per_mm);
    } else {
      const double from_low = static_cast<double>(n - s) / (n - 1);
      seg.nut = nut_low + from_low * (nut_high - nut_low);
      seg.bridge = bridge_low + from_low * (bridge_high - bridge_low);
    }
  }
  g.strings_in_instrument.resize(n);
  for (int s = 0; s < n; ++s) {
    g.strings_in_instrument[s].string = g.strings[s].string;
    g.strings_in_instrument[s].nut = g.world_from_instrument.InverseMap(g.strings[s].nut);
    g.strings_in_instrument[s].bridge = g.world_from_instrument.InverseMap(g.strings[s].bridge);
  }
  return g;
}

std::vector<StringSegment> StringsInWorld(const std::vector<StringSegment>& strings_in_instrument,
                                          const SimMatrix3d& world_from_instrument) {
  std::vector<StringSegment> out(strings_in_instrument.size());
  for (size_t i = 0; i < out.size(); ++i) {
    out[i].string = strings_in_instrument[i].string;
    out[i].nut = world_from_instrument * strings_in_instrument[i].nut;
    out[i].bridge = world_from_instrument * strings_in_instrument[i].bridge;
  }
  return out;
}

}  // namespace arco
