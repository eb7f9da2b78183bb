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
    if (n == "scroll_top") points[i] = {length + 185 * s, 0, -30 * s};
    if (n == "nut_l") points[i] = {length, 0.5 * model.nut_spacing_mm(), 0};
    if (n == "nut_r") points[i] = {length, -0.5 * model.nut_spacing_mm(), 0};
    if (n == "bridge_l") points[i] = {0, 0.5 * model.bridge_spacing_mm(), 0};
    if (n == "bridge_r") points[i] = {0, -0.5 * model.bridge_spacing_mm(), 0};
    if (n == "tail_gut") points[i] = {-342 * s, 0, -158 * s};
    if (n == "end_pin") points[i] = {-637 * s, 0, -284 * s};
  }
  return points;
}

std::vector<Eigen::Vector3d> NominalPoseKeypointsInInstrument(const InstrumentModel& model) {
  std::vector<Eigen::Vector3d> points = NominalKeypointsInInstrument(model);
  const auto& names = model.keypoint_names();
  for (size_t i = 0; i < names.size(); ++i) {
    if (names[i] == "end_pin") points[i].setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  return points;
}

}  // namespace arco
