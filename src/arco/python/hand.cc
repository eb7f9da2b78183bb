// arco.HandModel: forward kinematics and bounded fingertip IK.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "arco/hand/hand_model.h"
#include "arco/hand/hand_params.h"
#include "arco/hand/ik.h"
#include "arco/hand/kinematics.h"
#include "arco/python/bindings.h"

namespace arco::python {

// ---- hand ---------------------------------------------------------------------------

using PyHandModel = std::shared_ptr<const hand::HandModel>;
using HandParamsArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

PyHandModel MakeHandModel(const std::string& side,
                          const py::object& bone_lengths_mm,
                          const py::object& rest_points_mm) {
  hand::HandSide s;
  if (side == "left") {
    s = hand::HandSide::kLeft;
  } else if (side == "right") {
    s = hand::HandSide::kRight;
  } else {
    RaiseValueError("side must be left or right, got '" + side + "'");
  }
  hand::HandModel model = hand::HandModel::Default(s);
  if (!bone_lengths_mm.is_none() && !rest_points_mm.is_none()) {
    RaiseValueError("give bone_lengths_mm or rest_points_mm, not both");
  }
  if (!rest_points_mm.is_none()) {
    const auto points = rest_points_mm.cast<HandParamsArray>();
    if (points.ndim() != 2 || points.shape(0) != hand::kNumHandKeypoints || points.shape(1) != 3) {
      RaiseValueError("rest_points_mm must be (21, 3), got " + ShapeString(points));
    }
    hand::RestPointsMm p;
    for (int k = 0; k < hand::kNumHandKeypoints; ++k) {
      p[k] = Eigen::Vector3d(points.at(k, 0), points.at(k, 1), points.at(k, 2));
    }
    StatusOr<hand::HandModel> made = model.WithRestPoints(p);
    CheckValid(made.status());
    model = std::move(*made);
  }
  if (!bone_lengths_mm.is_none()) {
    const auto lengths = bone_lengths_mm.cast<HandParamsArray>();
    if (lengths.ndim() != 1 || lengths.shape(0) != hand::kNumHandKeypoints) {
      RaiseValueError("bone_lengths_mm must be (21,) (entry 0 unused), got " +
                      ShapeString(lengths));
    }
    hand::BoneLengthsMm l{};
    std::copy(lengths.data(), lengths.data() + hand::kNumHandKeypoints, l.begin());
    l[0] = 0;
    StatusOr<hand::HandModel> scaled = model.WithBoneLengths(l);
    CheckValid(scaled.status());
    model = std::move(*scaled);
  }
  return std::make_shared<const hand::HandModel>(std::move(model));
}

hand::HandPose PoseFromRow(const double* row) {
  hand::HandPose pose;
  pose.SetWristAngleAxis(Eigen::Vector3d(row[0], row[1], row[2]));
  pose.world_from_wrist.translation = Eigen::Vector3d(row[3], row[4], row[5]);
  std::copy(row + 6, row + hand::kHandParamsColumns, pose.angles_rad.begin());
  return pose;
}

std::vector<double> RowFromPose(const hand::HandPose& pose) {
  std::vector<double> row(hand::kHandParamsColumns);
  const Eigen::Vector3d aa = pose.WristAngleAxis();
  for (int k = 0; k < 3; ++k) {
    row[k] = aa[k];
    row[3 + k] = pose.world_from_wrist.translation[k];
  }
  std::copy(pose.angles_rad.begin(), pose.angles_rad.end(), row.begin() + 6);
  return row;
}

void CheckParamsShape(const py::array& params) {
  if (params.ndim() < 1 || params.shape(params.ndim() - 1) != hand::kHandParamsColumns) {
    RaiseValueError(
        "params must be (..., 26) [wrist angle-axis (3), wrist mm (3), 20 joint "
        "angles (rad)], got " +
        ShapeString(params));
  }
}

// (..., 26) hand_params rows -> (..., 21, 3) keypoints in world mm; NaN rows -> NaN.
py::array_t<double> ForwardKinematicsPy(const hand::HandModel& model,
                                        const HandParamsArray& params) {
  CheckParamsShape(params);
  const int64_t rows = params.size() / hand::kHandParamsColumns;
  std::vector<double> out(static_cast<size_t>(rows * hand::kNumHandKeypoints * 3), NAN);
  const double* data = params.data();
  {
    py::gil_scoped_release release;
    for (int64_t r = 0; r < rows; ++r) {
      const double* row = data + r * hand::kHandParamsColumns;
      if (!std::all_of(
              row, row + hand::kHandParamsColumns, [](double v) { return std::isfinite(v); })) {
        continue;
      }
      const hand::HandPointsMm points = hand::ForwardKinematics(model, PoseFromRow(row));
      for (int k = 0; k < hand::kNumHandKeypoints; ++k) {
        for (int c = 0; c < 3; ++c) out[(r * hand::kNumHandKeypoints + k) * 3 + c] = points[k][c];
      }
    }
  }
  std::vector<int64_t> shape(params.shape(), params.shape() + params.ndim() - 1);
  shape.push_back(hand::kNumHandKeypoints);
  shape.push_back(3);
  return ToArray(std::move(out), shape);
}

py::dict FingertipIkPy(const hand::HandModel& model,
                       const HandParamsArray& params,
                       int finger,
                       const HandParamsArray& target_mm,
                       const std::string& joints,
                       double reference_weight_mm_per_rad,
                       double max_change_deg,
                       bool exact_reach,
                       int max_iterations) {
  CheckParamsShape(params);
  if (params.ndim() != 1)
    RaiseValueError("params must be one (26,) row, got " + ShapeString(params));
  if (target_mm.ndim() != 1 || target_mm.shape(0) != 3) {
    RaiseValueError("target_mm must be (3,), got " + ShapeString(target_mm));
  }
  if (finger < 0 || finger >= hand::kNumFingers) {
    RaiseValueError("finger " + std::to_string(finger) + " outside 0..4 (0 = thumb, 1 = index)");
  }
  hand::FingerIkOptions options;
  bool known = false;
  for (hand::FingerIkJoints j : {hand::FingerIkJoints::kPipDip,
                                 hand::FingerIkJoints::kMcpFlexPipDip,
                                 hand::FingerIkJoints::kAll}) {
    if (joints == hand::FingerIkJointsName(j)) {
      options.joints = j;
      known = true;
    }
  }
  if (!known)
    RaiseValueError("joints must be pip_dip, mcp_flex_pip_dip or all, got '" + joints + "'");
  options.reference_weight_mm_per_rad = reference_weight_mm_per_rad;
  options.max_change_deg = max_change_deg;
  options.exact_reach = exact_reach;
  options.max_iterations = max_iterations;
  CheckValid(options.Validate());
  const hand::HandPose reference = PoseFromRow(params.data());
  const Eigen::Vector3d target(target_mm.data()[0], target_mm.data()[1], target_mm.data()[2]);
  hand::FingerIkResult r;
  {
    py::gil_scoped_release release;
    r = hand::SolveFingertipIk(
        model, reference, static_cast<hand::Finger>(finger), target, options);
  }
  if (!r.status.ok()) RaiseValueError(r.status.message());
  py::dict out;
  out["params"] = VectorToArray(RowFromPose(r.pose));
  out["converged"] = r.converged;
  out["iterations"] = r.iterations;
  out["initial_distance_mm"] = r.initial_distance_mm;
  out["final_distance_mm"] = r.final_distance_mm;
  out["active_limit_dofs"] = r.active_limit_dofs;
  out["step_limited"] = r.step_limited;
  out["termination"] = r.termination;
  return out;
}

void BindHand(py::module_& m) {
  py::class_<hand::HandModel, std::shared_ptr<hand::HandModel>>(
      m, "HandModel", "arco's 21-keypoint hand model (docs/hand.md)")
      .def(py::init([](const std::string& side,
                       const py::object& bone_lengths_mm,
                       const py::object& rest_points_mm) {
             return std::const_pointer_cast<hand::HandModel>(
                 MakeHandModel(side, bone_lengths_mm, rest_points_mm));
           }),
           "side"_a = "left",
           "bone_lengths_mm"_a = py::none(),
           "rest_points_mm"_a = py::none(),
           "The average adult hand, one with these (21,) bone lengths (entry 0 unused), or the "
           "performer's hand of a result (rest_points_mm (21, 3): read_result's, the fitted "
           "model's rest pose with the performer's palm)")
      .def_property_readonly("rest_points_mm",
                             [](const hand::HandModel& h) {
                               const hand::RestPointsMm p = h.rest_points_mm();
                               py::array_t<double> out({hand::kNumHandKeypoints, 3});
                               auto o = out.mutable_unchecked<2>();
                               for (int k = 0; k < hand::kNumHandKeypoints; ++k) {
                                 for (int c = 0; c < 3; ++c) o(k, c) = p[k][c];
                               }
                               return out;
                             })
      .def_property_readonly("side",
                             [](const hand::HandModel& h) { return hand::HandSideName(h.side()); })
      .def_property_readonly("bone_lengths_mm",
                             [](const hand::HandModel& h) {
                               const hand::BoneLengthsMm l = h.bone_lengths_mm();
                               return VectorToArray(std::vector<double>(l.begin(), l.end()));
                             })
      .def_property_readonly(
          "limits_rad",
          [](const hand::HandModel& h) {
            std::vector<double> v;
            for (int d = 0; d < hand::kNumJointDofs; ++d) {
              v.push_back(h.min_rad(d));
              v.push_back(h.max_rad(d));
            }
            return ToArray(std::move(v), {hand::kNumJointDofs, 2});
          },
          "(20, 2) [min, max] of each joint angle")
      .def_property_readonly_static("keypoint_names",
                                    [](const py::object&) {
                                      std::vector<std::string> names;
                                      for (int k = 0; k < hand::kNumHandKeypoints; ++k) {
                                        names.push_back(hand::KeypointName(k));
                                      }
                                      return names;
                                    })
      .def_property_readonly_static("dof_names",
                                    [](const py::object&) {
                                      std::vector<std::string> names;
                                      for (int d = 0; d < hand::kNumJointDofs; ++d) {
                                        names.push_back(hand::DofName(d));
                                      }
                                      return names;
                                    })
      .def("__repr__",
           [](const hand::HandModel& h) {
             return std::string("<arco.HandModel ") + hand::HandSideName(h.side()) + ">";
           })
      .def("forward_kinematics",
           &ForwardKinematicsPy,
           "params"_a,
           "(..., 26) hand_params rows -> (..., 21, 3) keypoints in world mm (NaN rows: NaN)")
      .def("fingertip_ik",
           &FingertipIkPy,
           "params"_a,
           "finger"_a,
           "target_mm"_a,
           py::kw_only(),
           "joints"_a = "pip_dip",
           "reference_weight_mm_per_rad"_a = hand::FingerIkOptions().reference_weight_mm_per_rad,
           "max_change_deg"_a = hand::FingerIkOptions().max_change_deg,
           "exact_reach"_a = hand::FingerIkOptions().exact_reach,
           "max_iterations"_a = hand::FingerIkOptions().max_iterations,
           R"(Bounded IK: move `finger` (0 thumb .. 4 little)'s tip to target_mm, only the
`joints` (pip_dip | mcp_flex_pip_dip | all) free, within the joint limits.

Returns a dict: params (26,), converged, iterations, initial_distance_mm, final_distance_mm,
active_limit_dofs, step_limited, termination.)");
}

}  // namespace arco::python
