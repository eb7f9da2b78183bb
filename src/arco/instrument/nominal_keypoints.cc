#include "arco/instrument/nominal_keypoints.h"

#include <limits>
#include <string>

namespace arco {

std::vector<Eigen::Vector3d> NominalKeypointsInInstrument(const InstrumentModel& model) {
  const double length = model.string_length_mm();
  const double s = length / kNominalReferenceCelloMm;
  const auto& names = model.keypoint_names();
  std::vector<Eigen::Vector3d> points(
      names.size(), Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string& n = names[i];
    if (n == "scroll_top") points[i] = {length + 186 * s, 0, -25 * s};
    if (n == "nut_l") points[i] = {length, 0.5 * model.nut_spacing_mm(), 0};
    if (n == "nut_r") points[i] = {length, -0.5 * model.nut_spacing_mm(), 0};
    if (n == "bridge_l") points[i] = {0, 0.5 * model.bridge_spacing_mm(), 0};
    if (n == "bridge_r") points[i] = {0, -0.5 * model.bridge_spacing_mm(), 0};
    if (n == "tail_gut") points[i] = {-377 * s, 0, -75 * s};
    if (n == "end_pin") points[i] = {-(377 + 314) * s, 0, -120 * s};
  }
  return points;
}

}  // namespace arco
