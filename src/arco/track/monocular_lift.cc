#include "arco/track/monocular_lift.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "arco/geometry/rotation.h"
#include "arco/track/one_view_pnp.h"
#include "arco/track/pose_solver.h"
#include "arco/util/number_range.h"
#include "arco/util/stats.h"

namespace arco::track {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// EPnP in RANSAC on undistorted pixels (one_view_pnp.h): the start of the refinement on
// the full camera model. Empty when RANSAC finds no pose in front of the camera.
std::optional<Rigid3d> InitialPose(const Camera& camera,
                                   const std::vector<PoseCorrespondence>& c,
                                   const MonocularLiftOptions& o) {
  std::vector<Eigen::Vector3d> object;
  std::vector<Eigen::Vector2d> image;
  for (const PoseCorrespondence& x : c) {
    object.push_back(x.point_in_template);
    image.push_back(camera.UndistortPixel(x.pixel));
  }
  Eigen::Matrix3d K;
  K << camera.fx, camera.skew, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1;
  const std::optional<OneViewPnp> pnp =
      EpnpInRansac(object, image, K, o.pnp_gate_px, o.min_instrument_points);
  if (!pnp || !(pnp->translation.z() > 0)) return std::nullopt;
  // world_from_template = world_from_cam * cam_from_template.
  const Eigen::Matrix3d& Rc = camera.cam_from_world.rotation;
  const Eigen::Vector3d& tc = camera.cam_from_world.translation;
  return Rigid3d(Eigen::Matrix3d(Rc.transpose() * pnp->cam_from_object.rotation),
                 Rc.transpose() * (pnp->translation - tc));
}

// The point of the ray through `pixel` at which it cuts the plane (point, normal); empty
// when the ray is flatter than min_cos to the plane or the cut is behind the camera.
std::optional<Eigen::Vector3d> CutPlane(const Camera& camera,
                                        const Eigen::Vector2d& pixel,
                                        const Eigen::Vector3d& point,
                                        const Eigen::Vector3d& normal,
                                        double min_cos) {
  const Eigen::Vector3d centre = camera.CenterInWorld();
  const Eigen::Vector3d ray = camera.RayInWorld(pixel);
  const double cos = ray.dot(normal);
  if (!(std::abs(cos) >= min_cos)) return std::nullopt;
  const double depth = (point - centre).dot(normal) / cos;
  if (!(depth > 0)) return std::nullopt;
  return centre + depth * ray;
}

// The point of the ray through `pixel` closest to the segment from a to b (extended by a
// quarter of its length at each end) and its distance to it; empty when it is behind the
// camera or the ray runs along the segment.
struct RayToSegment {
  Eigen::Vector3d on_ray;
  double distance;
};
std::optional<RayToSegment> NearestToSegment(const Camera& camera,
                                             const Eigen::Vector2d& pixel,
                                             const Eigen::Vector3d& a,
                                             const Eigen::Vector3d& b) {
  const Eigen::Vector3d centre = camera.CenterInWorld();
  const Eigen::Vector3d ray = camera.RayInWorld(pixel);
  const Eigen::Vector3d u = (b - a).normalized();
  // Closest points of the lines centre + s ray and a + t u (both directions unit).
  const Eigen::Vector3d w = centre - a;
  const double c = ray.dot(u), d = ray.dot(w), e = u.dot(w);
  const double denom = 1 - c * c;
  if (!(denom > 1e-9)) return std::nullopt;
  const double length = (b - a).norm();
  const double t = std::clamp((e - c * d) / denom, -0.25 * length, 1.25 * length);
  // The ray's point closest to the (clamped) point of the segment.
  const Eigen::Vector3d on_segment = a + t * u;
  const double s = ray.dot(on_segment - centre);
  if (!(s > 0)) return std::nullopt;
  return RayToSegment{centre + s * ray, (centre + s * ray - on_segment).norm()};
}

}  // namespace

Status MonocularLiftOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(CheckInRange("min_score", min_score, Closed(0, 1)));
  ARCO_RETURN_IF_ERROR(CheckInRange("min_instrument_points", min_instrument_points, Closed(4, 64)));
  ARCO_RETURN_IF_ERROR(CheckInRange("pnp_gate_px", pnp_gate_px, AboveZero(200)));
  ARCO_RETURN_IF_ERROR(CheckInRange("body_behind_mm", body_behind_mm, Closed(0, 2000)));
  ARCO_RETURN_IF_ERROR(CheckInRange("depth_window_frames", depth_window_frames, Closed(0, 300)));
  ARCO_RETURN_IF_ERROR(
      CheckInRange("end_pin_depth_window_frames", end_pin_depth_window_frames, Closed(0, 3000)));
  ARCO_RETURN_IF_ERROR(
      CheckInRange("rotation_window_frames", rotation_window_frames, Closed(0, 300)));
  return CheckInRange("min_ray_plane_cos", min_ray_plane_cos, AboveZero(1));
}

StatusOr<MonocularLift> LiftOneView(const Camera& camera,
                                    const NpyArray<double>& k,
                                    const MonocularScene& scene,
                                    const MonocularLiftOptions& o) {
  ARCO_RETURN_IF_ERROR(o.Validate());
  if (k.shape.size() != 4 || k.shape[1] != 1 || k.shape[3] != 3)
    return Status::Error("keypoints2d must be (F, 1, P, 3) for one view");
  const int64_t frames = k.shape[0], points = k.shape[2];
  if (scene.instrument_columns.size() != scene.instrument_points_mm.size())
    return Status::Error("the instrument's columns and points differ in number");
  auto inside = [&](int c) { return c >= 0 && c < points; };
  for (const std::vector<int>* columns : {&scene.instrument_columns,
                                          &scene.string_line_columns,
                                          &scene.string_line_depth_columns,
                                          &scene.unlifted_columns}) {
    if (!std::all_of(columns->begin(), columns->end(), inside))
      return Status::Error("a scene column is outside the keypoints' " + std::to_string(points));
  }
  if (std::abs(scene.front.norm() - 1) > 1e-6)
    return Status::Error("the instrument's front must be a unit vector");
  if (scene.strings_mm.empty()) return Status::Error("the scene has no strings");
  for (const auto& [nut, bridge] : scene.strings_mm) {
    if (!((bridge - nut).norm() > 0)) return Status::Error("a string's nut and bridge coincide");
  }

  // 0 body, 1 instrument, 2 string line, 3 not lifted.
  std::vector<uint8_t> kind(static_cast<size_t>(points), 0);
  for (int c : scene.string_line_columns) kind[static_cast<size_t>(c)] = 2;
  for (int c : scene.unlifted_columns) kind[static_cast<size_t>(c)] = 3;
  for (int c : scene.instrument_columns) kind[static_cast<size_t>(c)] = 1;

  MonocularLift out;
  out.points3d_mm.shape = {frames, points, 3};
  out.points3d_mm.data.assign(static_cast<size_t>(frames * points * 3), kNaN);
  out.depth_source.shape = {frames, points};
  out.depth_source.data.assign(static_cast<size_t>(frames * points), 0);
  out.pnp_rms_px.shape = {frames};
  out.pnp_rms_px.data.assign(static_cast<size_t>(frames), std::numeric_limits<float>::quiet_NaN());
  out.depth_sigma_mm.shape = {frames};
  out.depth_sigma_mm.data.assign(static_cast<size_t>(frames),
                                 std::numeric_limits<float>::quiet_NaN());
  out.world_from_instrument.assign(static_cast<size_t>(frames), std::nullopt);
  out.summary.frames = frames;

  PoseSolverOptions refine;
  refine.inlier_px = o.pnp_gate_px;
  refine.ransac_trials = 0;  // EPnP's RANSAC chose the start; only the refinement here
  refine.sample_size = o.min_instrument_points;
  const std::vector<Camera> cameras = {camera};
  const Eigen::Vector3d camera_axis = camera.cam_from_world.rotation.row(2).transpose();
  std::vector<double> rms;
  auto valid_at = [&](int64_t f, int64_t p) {
    return std::isfinite(k.at(f, 0, p, 0)) && std::isfinite(k.at(f, 0, p, 1)) &&
           k.at(f, 0, p, 2) >= o.min_score;
  };
  // 1. The instrument's pose in each frame on its own.
  std::vector<double> depth(static_cast<size_t>(frames), kNaN);  // its centre's, camera z
  Eigen::Vector3d centre_mm = Eigen::Vector3d::Zero();           // the strings' middle
  for (const auto& [nut, bridge] : scene.strings_mm) centre_mm += 0.5 * (nut + bridge);
  centre_mm /= static_cast<double>(scene.strings_mm.size());
  for (int64_t f = 0; f < frames; ++f) {
    std::vector<PoseCorrespondence> c;
    for (size_t i = 0; i < scene.instrument_columns.size(); ++i) {
      const int p = scene.instrument_columns[i];
      if (valid_at(f, p))
        c.push_back({0,
                     scene.instrument_points_mm[i],
                     Eigen::Vector2d(k.at(f, 0, p, 0), k.at(f, 0, p, 1)),
                     1.0});
    }
    if (static_cast<int>(c.size()) < o.min_instrument_points) continue;
    const std::optional<Rigid3d> start = InitialPose(camera, c, o);
    if (!start) continue;
    const std::optional<PoseSolution> solved =
        SolveRigidPose(cameras, c, *start, refine, o.min_instrument_points);
    if (!solved || !(solved->rms_px <= o.pnp_gate_px)) continue;
    out.world_from_instrument[static_cast<size_t>(f)] = solved->world_from_template;
    out.pnp_rms_px.data[static_cast<size_t>(f)] = static_cast<float>(solved->rms_px);
    depth[static_cast<size_t>(f)] =
        camera.PointInCamera(solved->world_from_template * centre_mm).z();
    rms.push_back(solved->rms_px);
    ++out.summary.frames_with_pose;
  }
  // 2. Its depth, the one thing a PnP of a 0.7 m body fixes poorly (a pixel of noise at
  // its ends moves it by centimetres), is the median over the frames around: the
  // instrument is held nearly still. The pose moves along the ray through its centre
  // (the image of the centre is kept).
  const Eigen::Vector3d camera_centre = camera.CenterInWorld();
  // Its orientation likewise: one view fixes the roll about the strings from the nut's
  // and the bridge's widths alone (24 and 48 mm on a cello), a few degrees of jitter per
  // frame where the held instrument turns by tenths. The Markley average over the frames
  // around (geometry/rotation.h), turned about the strings' middle (its image is kept).
  std::vector<Eigen::Quaterniond> rotations(static_cast<size_t>(frames));
  for (int64_t f = 0; f < frames; ++f) {
    if (out.world_from_instrument[static_cast<size_t>(f)])
      rotations[static_cast<size_t>(f)] =
          out.world_from_instrument[static_cast<size_t>(f)]->rotation;
  }
  const int64_t depth_window =
      scene.stands_on_end_pin ? o.end_pin_depth_window_frames : o.depth_window_frames;
  for (int64_t f = 0; f < frames && o.rotation_window_frames > 0; ++f) {
    std::optional<Rigid3d>& pose = out.world_from_instrument[static_cast<size_t>(f)];
    if (!pose) continue;
    std::vector<Eigen::Quaterniond> around;
    for (int64_t g = std::max<int64_t>(0, f - o.rotation_window_frames);
         g <= std::min(frames - 1, f + o.rotation_window_frames);
         ++g) {
      if (out.world_from_instrument[static_cast<size_t>(g)])
        around.push_back(rotations[static_cast<size_t>(g)]);
    }
    const Eigen::Vector3d centre = *pose * centre_mm;
    pose->rotation = *AverageQuaternions(around);
    pose->translation = centre - pose->rotation * centre_mm;
  }
  for (int64_t f = 0; f < frames; ++f) {
    std::optional<Rigid3d>& pose = out.world_from_instrument[static_cast<size_t>(f)];
    if (!pose) continue;
    std::vector<double> around;
    for (int64_t g = std::max<int64_t>(0, f - depth_window);
         g <= std::min(frames - 1, f + depth_window);
         ++g) {
      if (std::isfinite(depth[static_cast<size_t>(g)]))
        around.push_back(depth[static_cast<size_t>(g)]);
    }
    const double wanted = UpperMedian(around);
    out.depth_sigma_mm.data[static_cast<size_t>(f)] =
        static_cast<float>(kMadToSigma * MedianAbsDeviation(around, wanted));
    const double scale = wanted / depth[static_cast<size_t>(f)];
    const Eigen::Vector3d centre = *pose * centre_mm;
    pose->translation += (scale - 1) * (centre - camera_centre);
  }
  // 3. Every point of the frame from the instrument's pose.
  for (int64_t f = 0; f < frames; ++f) {
    if (!out.world_from_instrument[static_cast<size_t>(f)]) continue;
    const Rigid3d& pose = *out.world_from_instrument[static_cast<size_t>(f)];
    auto valid = [&](int64_t p) { return valid_at(f, p); };
    auto pixel = [&](int64_t p) { return Eigen::Vector2d(k.at(f, 0, p, 0), k.at(f, 0, p, 1)); };
    // The assumed plane: parallel to the image, behind the middle of the strings.
    const Eigen::Vector3d behind =
        pose * centre_mm - o.body_behind_mm * (pose.rotation * scene.front);
    auto put = [&](int64_t p, const Eigen::Vector3d& x, LiftDepth d) {
      for (int i = 0; i < 3; ++i) out.points3d_mm.at(f, p, i) = x[i];
      out.depth_source.at(f, p) = static_cast<uint8_t>(d);
      ++out.summary.lifted[static_cast<int>(d)];
    };
    for (size_t i = 0; i < scene.instrument_columns.size(); ++i)
      put(scene.instrument_columns[i],
          pose * scene.instrument_points_mm[i],
          LiftDepth::kInstrumentPose);
    for (int64_t p = 0; p < points; ++p) {
      const uint8_t what = kind[static_cast<size_t>(p)];
      if (what == 1 || what == 3 || !valid(p)) continue;
      if (what == 2) continue;  // below, together
      if (auto x = CutPlane(camera, pixel(p), behind, camera_axis, o.min_ray_plane_cos))
        put(p, *x, LiftDepth::kAssumedPlane);
    }
    // The hand at one depth: the median over its fingertips of the depth where each one's
    // ray passes closest to a string (the one it passes closest to). The hand's own shape
    // comes from the hand fit (bone lengths fixed), not from here.
    std::vector<double> depths;
    for (int p : scene.string_line_depth_columns) {
      if (!valid(p)) continue;
      std::optional<RayToSegment> best;
      for (const auto& [nut, bridge] : scene.strings_mm) {
        const auto x = NearestToSegment(camera, pixel(p), pose * nut, pose * bridge);
        if (x && (!best || x->distance < best->distance)) best = x;
      }
      if (best) depths.push_back(camera.PointInCamera(best->on_ray).z());
    }
    if (!depths.empty()) {
      const double depth = UpperMedian(depths);
      for (int p : scene.string_line_columns) {
        if (!valid(p)) continue;
        const Eigen::Vector2d n = camera.PixelToNormalized(pixel(p));
        const Eigen::Vector3d in_camera(n.x() * depth, n.y() * depth, depth);
        const RigidMatrix3d& c = camera.cam_from_world;
        put(p, c.rotation.transpose() * (in_camera - c.translation), LiftDepth::kStringLine);
      }
    }
  }
  out.summary.median_pnp_rms_px = UpperMedian(rms);  // NaN when none
  return out;
}

}  // namespace arco::track
