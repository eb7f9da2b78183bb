#include "arco/calibration/rig_calibration.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <set>
#include <stdexcept>

#include "arco/calibration/bundle_solver.h"
#include "arco/calibration/pose_parameters.h"
#include "arco/calibration/reprojection_cost.h"
#include "arco/geometry/alignment.h"
#include "arco/geometry/rotation.h"
#include "arco/geometry/triangulation.h"
#include "arco/util/check.h"
#include "arco/util/stats.h"

namespace arco::calibration {
namespace {

Camera CameraWithIntrinsics(const std::array<double, kNumIntrinsics>& intrinsics,
                            const RigidMatrix3d& cam_from_world) {
  Camera camera;
  camera.SetIntrinsics(intrinsics);
  camera.cam_from_world.rotation = cam_from_world.rotation;
  camera.cam_from_world.translation = cam_from_world.translation;
  return camera;
}

// The pixel residuals of a view for a board pose (cam_from_board); `reversed` reads the
// ids backwards (a chessboard's corners reported from the opposite corner).
std::vector<double> ViewErrors(const std::array<double, kNumIntrinsics>& intrinsics,
                               const RigidMatrix3d& cam_from_board,
                               const std::vector<Eigen::Vector3d>& points,
                               const BoardView& view,
                               bool reversed) {
  const Camera camera = CameraWithIntrinsics(intrinsics, cam_from_board);
  std::vector<double> errors;
  errors.reserve(view.point_ids.size());
  const int n = static_cast<int>(points.size());
  for (size_t i = 0; i < view.point_ids.size(); ++i) {
    const int id = reversed ? n - 1 - view.point_ids[i] : view.point_ids[i];
    const auto pixel = camera.Project(points[id]);
    errors.push_back(pixel ? (*pixel - view.corners_px[i]).norm() : 1e9);
  }
  return errors;
}

// Views spread over the image: greedy, each step the view whose corners fall in the least
// covered cells of an 8 x 6 grid (diminishing returns per cell), ties to the earlier view.
std::vector<int> SelectViewsCoveringImage(const CameraBoardViews& camera, int max_views) {
  const int n = static_cast<int>(camera.views.size());
  std::vector<int> chosen;
  if (n <= max_views) {
    chosen.resize(n);
    std::iota(chosen.begin(), chosen.end(), 0);
    return chosen;
  }
  constexpr int kCols = 8, kRows = 6;
  auto cell = [&](const Eigen::Vector2d& p) {
    const int cx = std::clamp(static_cast<int>(p.x() / camera.width * kCols), 0, kCols - 1);
    const int cy = std::clamp(static_cast<int>(p.y() / camera.height * kRows), 0, kRows - 1);
    return cy * kCols + cx;
  };
  std::vector<int> covered(kCols * kRows, 0);
  std::vector<bool> taken(n, false);
  for (int k = 0; k < max_views; ++k) {
    int best = -1;
    double best_score = -1;
    for (int v = 0; v < n; ++v) {
      if (taken[v]) continue;
      double score = 0;
      for (const auto& p : camera.views[v].corners_px) score += 1.0 / (1 + covered[cell(p)]);
      if (score > best_score) best_score = score, best = v;
    }
    taken[best] = true;
    chosen.push_back(best);
    for (const auto& p : camera.views[best].corners_px) ++covered[cell(p)];
  }
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

// Zhang's method through OpenCV, expressed in arco's model (skew 0).
StatusOr<std::array<double, kNumIntrinsics>> CalibrateIntrinsics(
    const CameraBoardViews& camera, const std::vector<Eigen::Vector3d>& points, int max_views) {
  // cv::Mat per view, not std::vector: OpenCV's results depend in the last bits on where its
  // inputs lie in memory (its SIMD loops start on an aligned element, so the split between
  // vector and scalar sums moves with the buffer's address: rig_calibration_test's repeat
  // runs differed by ~1e-12 with std::vector inputs); cv::Mat data is always allocated
  // 64-byte aligned, so the same input gives the same result every run.
  std::vector<cv::Mat> object_points;
  std::vector<cv::Mat> image_points;
  for (int v : SelectViewsCoveringImage(camera, max_views)) {
    const BoardView& view = camera.views[v];
    if (view.point_ids.size() < 6) continue;
    const int n = static_cast<int>(view.point_ids.size());
    cv::Mat object(n, 1, CV_32FC3), image(n, 1, CV_32FC2);
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d& p = points[view.point_ids[i]];
      object.at<cv::Vec3f>(i) = cv::Vec3f(p.x(), p.y(), p.z());
      image.at<cv::Vec2f>(i) = cv::Vec2f(view.corners_px[i].x(), view.corners_px[i].y());
    }
    object_points.push_back(object);
    image_points.push_back(image);
  }
  if (object_points.size() < 3)
    return Status::Error(camera.camera + " (" + camera.source + "): only " +
                         std::to_string(object_points.size()) +
                         " usable board views; at least 3 are needed to estimate its "
                         "intrinsics (or give them)");
  cv::Mat K, dist;
  std::vector<cv::Mat> rvecs, tvecs;
  try {
    // OpenCV's own thread pool could split calibrateCamera's sums in a varying order:
    // one thread, so the thread count plays no part.
    const int opencv_threads = cv::getNumThreads();
    cv::setNumThreads(1);
    struct Restore {
      int n;
      ~Restore() { cv::setNumThreads(n); }
    } restore{opencv_threads};
    cv::calibrateCamera(
        object_points,
        image_points,
        cv::Size(camera.width, camera.height),
        K,
        dist,
        rvecs,
        tvecs,
        0,
        cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-12));
  } catch (const cv::Exception& e) {
    return Status::Error(camera.camera + " (" + camera.source +
                         "): the intrinsics could not be estimated: " + e.what());
  }
  std::array<double, kNumIntrinsics> in{};
  in[kFx] = K.at<double>(0, 0);
  in[kFy] = K.at<double>(1, 1);
  in[kCx] = K.at<double>(0, 2);
  in[kCy] = K.at<double>(1, 2);
  in[kK1] = dist.at<double>(0);
  in[kK2] = dist.at<double>(1);
  in[kP1] = dist.at<double>(2);
  in[kP2] = dist.at<double>(3);
  in[kK3] = dist.at<double>(4);
  // calibrateCamera's result is not bit-repeatable: from the same inputs, runs of the same
  // binary differ (inputs moved in memory change fx by a few ulps, rig_calibration_test; on
  // OpenCV's left/right chessboard pairs two outcomes alternate between processes, fx 2e-9
  // px, cy 3e-8 px, k1 7e-11 apart: its Levenberg-Marquardt amplifies the last bits), and
  // everything after it starts from these values. Rounded to 1e-3 px and 1e-6 (far below any
  // calibration's precision: 1e-6 in k1 moves a corner pixel by 3e-4 px; far above those
  // differences), the start is the same every run: a difference straddles a rounding step
  // with a chance of about its size over the step, 3e-5 for cy, 5e-4 per camera in all. The
  // former steps (1e-6 px, 1e-9) were straddled by fx on those pairs in half the runs.
  for (int i : {kFx, kFy, kCx, kCy}) in[i] = std::round(in[i] * 1e3) / 1e3;
  for (int i : {kK1, kK2, kK3, kP1, kP2}) in[i] = std::round(in[i] * 1e6) / 1e6;
  for (double v : in)
    if (!std::isfinite(v))
      return Status::Error(camera.camera + " (" + camera.source +
                           "): the intrinsics could not be estimated (not finite)");
  return in;
}

// cam_from_board of one view by PnP (OpenCV's iterative solver from the homography).
std::optional<RigidMatrix3d> BoardPose(const std::array<double, kNumIntrinsics>& in,
                                       const std::vector<Eigen::Vector3d>& points,
                                       const BoardView& view) {
  if (view.point_ids.size() < 4) return std::nullopt;
  // cv::Mat (64-byte aligned) for the same reason as in CalibrateIntrinsics.
  const int n = static_cast<int>(view.point_ids.size());
  cv::Mat object(n, 1, CV_64FC3), image(n, 1, CV_64FC2);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d& p = points[view.point_ids[i]];
    object.at<cv::Vec3d>(i) = cv::Vec3d(p.x(), p.y(), p.z());
    image.at<cv::Vec2d>(i) = cv::Vec2d(view.corners_px[i].x(), view.corners_px[i].y());
  }
  const cv::Matx33d K(in[kFx], in[kSkew], in[kCx], 0, in[kFy], in[kCy], 0, 0, 1);
  const cv::Vec<double, 5> dist(in[kK1], in[kK2], in[kP1], in[kP2], in[kK3]);
  cv::Vec3d rvec, tvec;
  try {
    if (!cv::solvePnP(object, image, K, dist, rvec, tvec, false, cv::SOLVEPNP_ITERATIVE))
      return std::nullopt;
  } catch (const cv::Exception&) {
    return std::nullopt;
  }
  RigidMatrix3d pose;
  pose.rotation = RotationFromAxisAngle(Eigen::Vector3d(rvec[0], rvec[1], rvec[2]));
  pose.translation = Eigen::Vector3d(tvec[0], tvec[1], tvec[2]);
  if (!pose.rotation.allFinite() || !pose.translation.allFinite() || pose.translation.z() <= 0)
    return std::nullopt;
  return pose;
}

// The relative pose b_from_a from per-frame estimates: the estimate most others agree with
// (within 5 degrees and 10 % of the baseline + 10 mm: loose, as one view's PnP of a small or
// distant board is; a backward chessboard or another instant is far off), then the mean of
// those that agree; *support = how many agree.
RigidMatrix3d ConsensusPose(const std::vector<RigidMatrix3d>& candidates, int* support) {
  ARCO_CHECK(!candidates.empty());
  auto agree = [](const RigidMatrix3d& a, const RigidMatrix3d& b) {
    return RotationAngleBetween(a.rotation, b.rotation) < 5.0 * M_PI / 180 &&
           (a.translation - b.translation).norm() < 0.1 * a.translation.norm() + 10.0;
  };
  size_t best = 0;
  int best_count = -1;
  for (size_t i = 0; i < candidates.size(); ++i) {
    int count = 0;
    for (const RigidMatrix3d& other : candidates) count += agree(candidates[i], other);
    if (count > best_count) best_count = count, best = i;
  }
  Eigen::Matrix3d rotation_sum = Eigen::Matrix3d::Zero();
  Eigen::Vector3d translation_sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (const RigidMatrix3d& other : candidates)
    if (agree(candidates[best], other)) {
      rotation_sum += other.rotation;
      translation_sum += other.translation;
      ++n;
    }
  *support = n;
  return {NearestRotation(rotation_sum / n), translation_sum / n};
}

// Reprojection of one board corner: x_cam = cam_from_world * world_from_board * X.
struct BoardCornerCost {
  BoardCornerCost(const Eigen::Vector3d& point_in_board, const Eigen::Vector2d& observed_px)
      : point_in_board(point_in_board), observed_px(observed_px) {}
  template <typename T>
  bool operator()(const T* cam_from_world,
                  const T* world_from_board,
                  const T* intrinsics,
                  T* residual) const {
    const T board_point[3] = {T(point_in_board.x()), T(point_in_board.y()), T(point_in_board.z())};
    T world_point[3];
    TransformByPose(world_from_board, board_point, world_point);
    return ReprojectionResidual(cam_from_world, intrinsics, world_point, observed_px, residual);
  }
  Eigen::Vector3d point_in_board;
  Eigen::Vector2d observed_px;
};

// A view of a camera in the bundle adjustment.
struct UsedView {
  int camera = 0;
  int view = 0;  // index into CameraBoardViews::views
  bool reversed = false;
};

}  // namespace

Status RigCalibrationOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(
      CheckInRange("max_intrinsic_views", max_intrinsic_views, kIntrinsicViewsRange));
  ARCO_RETURN_IF_ERROR(CheckInRange("loss_scale_px", loss_scale_px, kLossScaleRangePx));
  ARCO_RETURN_IF_ERROR(CheckInRange("max_iterations", max_iterations, kIterationsRange));
  ARCO_RETURN_IF_ERROR(CheckInRange("high_residual_px", high_residual_px, kHighResidualRangePx));
  ARCO_RETURN_IF_ERROR(CheckInRange("min_views", min_views, kMinViewsRange));
  return Status::Ok();
}

nlohmann::ordered_json RigCalibrationReport::ToJson() const {
  nlohmann::ordered_json j;
  j["board"] = board;
  j["origin"] = origin;
  j["units"] = "mm";
  j["rms_px"] = rms_px;
  j["board_triangulation"] = {
      {"points", board_points}, {"rms_mm", board_rms_mm}, {"p95_mm", board_p95_mm}};
  j["cameras"] = nlohmann::ordered_json::array();
  for (const CameraReport& c : cameras)
    j["cameras"].push_back({{"name", c.name},
                            {"views", c.views},
                            {"views_used", c.views_used},
                            {"observations", c.observations},
                            {"rms_px", c.rms_px},
                            {"p95_px", c.p95_px},
                            {"intrinsics_given", c.intrinsics_given}});
  j["pairs"] = nlohmann::ordered_json::array();
  for (const PairReport& p : pairs)
    j["pairs"].push_back(
        {{"cameras", {p.camera_a, p.camera_b}}, {"shared_frames", p.shared_frames}});
  j["bundle_adjustment"] = {{"termination", bundle_adjustment.termination},
                            {"iterations", bundle_adjustment.iterations},
                            {"initial_cost", bundle_adjustment.initial_cost},
                            {"final_cost", bundle_adjustment.final_cost},
                            {"residual_blocks", bundle_adjustment.residual_blocks},
                            {"board_poses", bundle_adjustment.board_poses}};
  // No solve time here: the report of the same inputs is the same bytes (the command
  // prints the time).
  j["warnings"] = nlohmann::ordered_json::array();
  for (const CalibrationWarning& w : warnings)
    j["warnings"].push_back({{"code", w.code}, {"camera", w.camera}, {"message", w.message}});
  return j;
}

StatusOr<RigCalibration> CalibrateRig(const RigCalibrationOptions& options,
                                      const BoardSpec& board,
                                      const std::vector<CameraBoardViews>& cameras,
                                      const Rig* initial,
                                      Progress& progress) {
  if (Status s = options.Validate(); !s.ok()) throw std::invalid_argument(s.message());
  if (Status s = board.Validate(); !s.ok()) throw std::invalid_argument(s.message());
  const int num_cameras = static_cast<int>(cameras.size());
  const std::vector<Eigen::Vector3d> points = board.PointsInBoard();
  for (const CameraBoardViews& c : cameras)
    for (const BoardView& v : c.views) {
      if (v.point_ids.size() != v.corners_px.size())
        throw std::invalid_argument("CalibrateRig: point_ids and corners_px differ in size");
      for (int id : v.point_ids)
        if (id < 0 || id >= board.num_points())
          throw std::invalid_argument("CalibrateRig: a point id is outside the board");
    }

  if (num_cameras < 2)
    return Status::Error("a rig calibration needs at least two cameras, got " +
                         std::to_string(num_cameras) +
                         (num_cameras == 1 ? " (" + cameras[0].camera + ")" : std::string()));
  std::map<std::string, int> camera_index;
  for (int c = 0; c < num_cameras; ++c) {
    if (!camera_index.emplace(cameras[c].camera, c).second)
      return Status::Error("camera '" + cameras[c].camera + "' is given twice");
    if (cameras[c].width <= 0 || cameras[c].height <= 0)
      throw std::invalid_argument("CalibrateRig: camera " + cameras[c].camera +
                                  " has no image size");
  }
  for (const CameraBoardViews& c : cameras)
    if (c.views.empty())
      return Status::Error(c.source + ": no board (" + board.ToString() + ") found in " +
                           std::to_string(c.frames_read) + " frames of camera " + c.camera);
  int root = 0;
  const bool board_origin = options.origin == "board";
  if (!options.origin.empty() && !board_origin) {
    auto it = camera_index.find(options.origin);
    if (it == camera_index.end())
      return Status::Error("origin '" + options.origin +
                           "' is neither 'board' nor one of the cameras");
    root = it->second;
  }

  // 1. Intrinsics.
  progress.StartStage(1, 3, "initial poses");
  progress.SetTotal(num_cameras);
  std::vector<std::array<double, kNumIntrinsics>> intrinsics(num_cameras);
  std::vector<char> given(num_cameras, 0);
  // One camera after the other: OpenCV parallelises calibrateCamera itself.
  for (int c = 0; c < num_cameras; ++c) {
    const int index = initial != nullptr ? initial->FindCamera(cameras[c].camera) : -1;
    if (index >= 0) {
      const Camera& known = initial->cameras[index];
      if (known.width != cameras[c].width || known.height != cameras[c].height)
        return Status::Error("camera " + cameras[c].camera + ": the given intrinsics are for " +
                             std::to_string(known.width) + "x" + std::to_string(known.height) +
                             " images, its frames are " + std::to_string(cameras[c].width) + "x" +
                             std::to_string(cameras[c].height));
      intrinsics[c] = known.Intrinsics();
      given[c] = 1;
    } else {
      ARCO_ASSIGN_OR_RETURN(intrinsics[c],
                            CalibrateIntrinsics(cameras[c], points, options.max_intrinsic_views));
    }
    progress.Advance(1);
  }

  // 2. Board pose in every view; frames -> views.
  std::vector<std::vector<std::optional<RigidMatrix3d>>> cam_from_board(num_cameras);
  std::map<int64_t, std::vector<std::pair<int, int>>> frames;  // frame -> (camera, view)
  for (int c = 0; c < num_cameras; ++c) {
    cam_from_board[c].resize(cameras[c].views.size());
    for (size_t v = 0; v < cameras[c].views.size(); ++v) {
      cam_from_board[c][v] = BoardPose(intrinsics[c], points, cameras[c].views[v]);
      if (cam_from_board[c][v])
        frames[cameras[c].views[v].frame].emplace_back(c, static_cast<int>(v));
    }
  }

  // 3. Camera graph and its maximum spanning tree (Prim from the root).
  Eigen::MatrixXi shared = Eigen::MatrixXi::Zero(num_cameras, num_cameras);
  for (const auto& [frame, views] : frames)
    for (size_t i = 0; i < views.size(); ++i)
      for (size_t j = i + 1; j < views.size(); ++j) {
        ++shared(views[i].first, views[j].first);
        ++shared(views[j].first, views[i].first);
      }
  std::vector<int> parent(num_cameras, -1);
  std::vector<bool> in_tree(num_cameras, false);
  std::vector<int> order = {root};
  in_tree[root] = true;
  while (true) {
    int best_a = -1, best_b = -1, best_w = 0;
    for (int a = 0; a < num_cameras; ++a)
      if (in_tree[a])
        for (int b = 0; b < num_cameras; ++b)
          if (!in_tree[b] && shared(a, b) > best_w) best_w = shared(a, b), best_a = a, best_b = b;
    if (best_b < 0) break;
    in_tree[best_b] = true;
    parent[best_b] = best_a;
    order.push_back(best_b);
  }
  if (static_cast<int>(order.size()) < num_cameras) {
    // The connected groups, for the message.
    std::vector<int> group(num_cameras, -1);
    std::string groups;
    int num_groups = 0;
    for (int s = 0; s < num_cameras; ++s) {
      if (group[s] >= 0) continue;
      std::vector<int> stack = {s};
      group[s] = num_groups;
      std::string names;
      while (!stack.empty()) {
        const int a = stack.back();
        stack.pop_back();
        names += (names.empty() ? "" : ", ") + cameras[a].camera;
        for (int b = 0; b < num_cameras; ++b)
          if (group[b] < 0 && shared(a, b) > 0) group[b] = num_groups, stack.push_back(b);
      }
      groups += (groups.empty() ? "{" : " | {") + names + "}";
      ++num_groups;
    }
    std::string lonely;
    for (int c = 0; c < num_cameras; ++c)
      if (!in_tree[c]) lonely += (lonely.empty() ? "" : ", ") + cameras[c].camera;
    return Status::Error("disconnected camera graph: " + lonely + " share" +
                         (lonely.find(',') == std::string::npos ? "s" : "") +
                         " no board frame with " + cameras[root].camera +
                         "'s group; groups that see the board together: " + groups);
  }

  // 4. cam_from_world along the tree.
  std::vector<RigidMatrix3d> cam_from_world(num_cameras);
  std::vector<CalibrationWarning> weak_links;
  for (size_t k = 1; k < order.size(); ++k) {
    const int c = order[k], p = parent[c];
    std::vector<RigidMatrix3d> candidates;
    for (const auto& [frame, views] : frames) {
      int vp = -1, vc = -1;
      for (const auto& [cam, view] : views) {
        if (cam == p) vp = view;
        if (cam == c) vc = view;
      }
      if (vp >= 0 && vc >= 0)
        candidates.push_back(*cam_from_board[c][vc] * cam_from_board[p][vp]->Inverse());
    }
    int support = 0;
    cam_from_world[c] = ConsensusPose(candidates, &support) * cam_from_world[p];
    // Frames that disagree on the relative pose (most of them) mean unsynchronised videos
    // or wrong detections: a rig built on one of them would look consistent and be wrong.
    const int n = static_cast<int>(candidates.size());
    if (n >= 3 && 2 * support < n)
      return Status::Error("cameras " + cameras[p].camera + " and " + cameras[c].camera +
                           ": their " + std::to_string(n) +
                           " shared frames disagree on the relative pose (at most " +
                           std::to_string(support) + " agree): are the videos synchronised?");
    if (n < 3)
      weak_links.push_back({"weak_link",
                            cameras[c].camera,
                            cameras[c].camera + " is joined to the rig through " +
                                std::to_string(n) + " frame" + (n == 1 ? "" : "s") +
                                " shared with " + cameras[p].camera +
                                ", too few to check: film the board in view of both longer"});
  }

  // 5. Board pose per frame: the view estimate that best explains the frame's other views;
  // views it cannot explain (a bad detection) are left out; a chessboard view whose ids
  // read backwards fit is reversed (the 180-degree ambiguity of a chessboard's corners).
  const bool chessboard = board.kind == BoardKind::kChessboard;
  const double reject_px = std::max(20.0, 10 * options.loss_scale_px);
  std::vector<int64_t> ba_frames;
  std::vector<RigidMatrix3d> world_from_board;
  std::vector<std::vector<UsedView>> ba_views;
  for (const auto& [frame, views] : frames) {
    if (views.size() < 2 && !options.refine_intrinsics) continue;
    double best_cost = std::numeric_limits<double>::infinity();
    RigidMatrix3d best;
    for (const auto& [cam, view] : views) {
      const RigidMatrix3d candidate = cam_from_world[cam].Inverse() * *cam_from_board[cam][view];
      std::vector<double> medians;
      for (const auto& [cam2, view2] : views) {
        const RigidMatrix3d cb = cam_from_world[cam2] * candidate;
        std::vector<double> e =
            ViewErrors(intrinsics[cam2], cb, points, cameras[cam2].views[view2], false);
        medians.push_back(Median(e));
      }
      const double cost = Median(medians);
      if (cost < best_cost) best_cost = cost, best = candidate;
    }
    std::vector<UsedView> used;
    for (const auto& [cam, view] : views) {
      const RigidMatrix3d cb = cam_from_world[cam] * best;
      const BoardView& v = cameras[cam].views[view];
      const double forward = Median(ViewErrors(intrinsics[cam], cb, points, v, false));
      const double backward =
          chessboard ? Median(ViewErrors(intrinsics[cam], cb, points, v, true)) : 1e9;
      if (std::min(forward, backward) > reject_px) continue;
      used.push_back({cam, view, backward < forward});
    }
    if (used.size() < 2 && !(options.refine_intrinsics && used.size() == 1)) continue;
    ba_frames.push_back(frame);
    world_from_board.push_back(best);
    ba_views.push_back(std::move(used));
  }

  // Every camera must keep a view in a frame that another camera's view agrees with, else
  // nothing ties it to the rig.
  std::vector<int> shared_used(num_cameras, 0);
  for (const auto& used : ba_views)
    if (used.size() >= 2)
      for (const UsedView& u : used) ++shared_used[u.camera];
  for (int c = 0; c < num_cameras; ++c)
    if (shared_used[c] == 0)
      return Status::Error("camera " + cameras[c].camera + " (" + cameras[c].source +
                           "): none of its board views agrees with the other cameras' views of "
                           "the same frames (are the videos synchronised?)");

  // 6. Bundle adjustment.
  progress.StartStage(2, 3, "bundle adjustment");
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::array<double, 6>> camera_params(num_cameras);
  for (int c = 0; c < num_cameras; ++c) camera_params[c] = ParamsFromRigid(cam_from_world[c]);
  std::vector<std::array<double, 6>> board_params(ba_frames.size());
  for (size_t f = 0; f < ba_frames.size(); ++f)
    board_params[f] = ParamsFromRigid(world_from_board[f]);
  // Every camera's pose and intrinsics in one buffer, camera after camera. Ceres orders the
  // blocks of an elimination group by their addresses (ParameterBlockOrdering keeps a
  // std::set<double*>): with the poses and the intrinsics in two separate allocations, their
  // order in the reduced camera system depended on where the heap put them, and repeat runs
  // differed in the last bits (~1e-12).
  constexpr int kStride = 6 + kNumIntrinsics;
  std::vector<double> camera_buffer(static_cast<size_t>(num_cameras) * kStride);
  auto pose_block = [&](int c) { return &camera_buffer[static_cast<size_t>(c) * kStride]; };
  auto intrinsics_block = [&](int c) { return pose_block(c) + 6; };
  for (int c = 0; c < num_cameras; ++c) {
    std::copy(camera_params[c].begin(), camera_params[c].end(), pose_block(c));
    std::copy(intrinsics[c].begin(), intrinsics[c].end(), intrinsics_block(c));
  }
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::HuberLoss loss(options.loss_scale_px);
  const int n_points = board.num_points();
  for (size_t f = 0; f < ba_frames.size(); ++f)
    for (const UsedView& u : ba_views[f]) {
      const BoardView& v = cameras[u.camera].views[u.view];
      for (size_t i = 0; i < v.point_ids.size(); ++i) {
        const int id = u.reversed ? n_points - 1 - v.point_ids[i] : v.point_ids[i];
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<BoardCornerCost, 2, 6, 6, kNumIntrinsics>(
                new BoardCornerCost(points[id], v.corners_px[i])),
            &loss,
            pose_block(u.camera),
            board_params[f].data(),
            intrinsics_block(u.camera));
      }
    }
  for (int c = 0; c < num_cameras; ++c) {
    if (!problem.HasParameterBlock(pose_block(c))) continue;
    if (c == root) problem.SetParameterBlockConstant(pose_block(c));
    if (!options.refine_intrinsics)
      problem.SetParameterBlockConstant(intrinsics_block(c));
    else
      problem.SetManifold(intrinsics_block(c), new ceres::SubsetManifold(kNumIntrinsics, {kSkew}));
  }
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (auto& b : board_params) ordering->AddElementToGroup(b.data(), 0);
  for (int c = 0; c < num_cameras; ++c) {
    if (!problem.HasParameterBlock(pose_block(c))) continue;
    ordering->AddElementToGroup(pose_block(c), 1);
    ordering->AddElementToGroup(intrinsics_block(c), 1);
  }
  // One thread inside (bundle_solver.h): the adjustment takes about a second.
  ARCO_ASSIGN_OR_RETURN(const BundleAdjustmentSummary solved,
                        SolveBundle(&problem, ordering, options.max_iterations, start));
  for (int c = 0; c < num_cameras; ++c) {
    std::copy(pose_block(c), pose_block(c) + 6, camera_params[c].begin());
    std::copy(intrinsics_block(c), intrinsics_block(c) + kNumIntrinsics, intrinsics[c].begin());
  }

  RigCalibration result;
  RigCalibrationReport& report = result.report;
  report.board = board.ToString();
  report.bundle_adjustment = solved;
  report.bundle_adjustment.board_poses = static_cast<int>(ba_frames.size());

  // 7. World frame, the rig and the report.
  progress.StartStage(3, 3, "report");
  RigidMatrix3d world_from_new;  // the chosen world in the adjustment's world
  report.origin = cameras[root].camera;
  if (board_origin) {
    for (size_t f = 0; f < ba_frames.size(); ++f)
      if (ba_views[f].size() >= 2) {
        world_from_new = RigidFromParams(board_params[f].data());
        report.origin = "board@" + std::to_string(ba_frames[f]);
        break;
      }
  }
  result.rig.units = "mm";
  for (int c = 0; c < num_cameras; ++c) {
    const RigidMatrix3d pose = RigidFromParams(camera_params[c].data()) * world_from_new;
    Camera camera = CameraWithIntrinsics(intrinsics[c], pose);
    camera.name = cameras[c].camera;
    camera.width = cameras[c].width;
    camera.height = cameras[c].height;
    result.rig.cameras.push_back(camera);
  }

  // Two cameras in one place (the same video given twice, or copies of it) make a rig that
  // triangulates nothing: an error, not a calibration. 1 % of a board square is far below
  // any real baseline and far above the adjustment's noise on identical views.
  for (int a = 0; a < num_cameras; ++a)
    for (int b = a + 1; b < num_cameras; ++b) {
      const double baseline_mm =
          (result.rig.cameras[a].CenterInWorld() - result.rig.cameras[b].CenterInWorld()).norm();
      if (!(baseline_mm >= 0.01 * board.square_mm))
        return Status::Error("cameras " + cameras[a].camera + " (" + cameras[a].source + ") and " +
                             cameras[b].camera + " (" + cameras[b].source + ") are " +
                             NumberText(std::round(baseline_mm * 1000) / 1000) +
                             " mm apart: a rig needs a baseline (the same video given twice?)");
    }

  std::vector<std::vector<double>> errors(num_cameras);
  std::vector<int> views_used(num_cameras, 0);
  for (size_t f = 0; f < ba_frames.size(); ++f) {
    const RigidMatrix3d new_from_board =
        world_from_new.Inverse() * RigidFromParams(board_params[f].data());
    for (const UsedView& u : ba_views[f]) {
      const Camera& cam = result.rig.cameras[u.camera];
      const RigidMatrix3d cam_from_board = cam.cam_from_world * new_from_board;
      const std::vector<double> e = ViewErrors(intrinsics[u.camera],
                                               cam_from_board,
                                               points,
                                               cameras[u.camera].views[u.view],
                                               u.reversed);
      errors[u.camera].insert(errors[u.camera].end(), e.begin(), e.end());
      ++views_used[u.camera];
    }
  }
  std::vector<double> all_errors;
  for (int c = 0; c < num_cameras; ++c) {
    CameraReport r;
    r.name = cameras[c].camera;
    r.views = static_cast<int>(cameras[c].views.size());
    r.views_used = views_used[c];
    r.observations = static_cast<int>(errors[c].size());
    r.rms_px = Rms(errors[c]);
    r.p95_px = errors[c].empty() ? 0 : InterpolatedQuantile(errors[c], 0.95);
    r.intrinsics_given = given[c] != 0;
    report.cameras.push_back(r);
    all_errors.insert(all_errors.end(), errors[c].begin(), errors[c].end());
  }
  report.rms_px = Rms(all_errors);
  for (int a = 0; a < num_cameras; ++a)
    for (int b = a + 1; b < num_cameras; ++b)
      if (shared(a, b) > 0)
        report.pairs.push_back({cameras[a].camera, cameras[b].camera, shared(a, b)});

  // Board corners triangulated (DLT on undistorted normalised coordinates) and compared
  // with the board after a rigid fit per frame.
  std::vector<Eigen::Vector3d> centres;
  for (const Camera& cam : result.rig.cameras) centres.push_back(cam.CenterInWorld());
  const WorldConditioning conditioning = ConditioningFromCameraCenters(centres);
  std::vector<double> board_errors;
  for (size_t f = 0; f < ba_frames.size(); ++f) {
    if (ba_views[f].size() < 2) continue;
    std::map<int, std::vector<DltObservation>> by_point;
    for (const UsedView& u : ba_views[f]) {
      const Camera& cam = result.rig.cameras[u.camera];
      Matrix34d P;
      P.leftCols<3>() = cam.cam_from_world.rotation;
      P.col(3) = cam.cam_from_world.translation;
      const BoardView& v = cameras[u.camera].views[u.view];
      for (size_t i = 0; i < v.point_ids.size(); ++i) {
        const int id = u.reversed ? n_points - 1 - v.point_ids[i] : v.point_ids[i];
        by_point[id].push_back({P, cam.PixelToNormalized(v.corners_px[i]), 1.0});
      }
    }
    std::vector<Eigen::Vector3d> source, target;
    for (const auto& [id, observations] : by_point) {
      if (observations.size() < 2) continue;
      const auto point = TriangulateDlt(observations, conditioning);
      if (!point) continue;
      source.push_back(points[id]);
      target.push_back(*point);
    }
    const auto fit = AlignPoints(source, target, {}, AlignmentOptions());
    if (!fit) continue;
    board_errors.insert(board_errors.end(), fit->residuals.begin(), fit->residuals.end());
  }
  report.board_points = static_cast<int>(board_errors.size());
  report.board_rms_mm = Rms(board_errors);
  report.board_p95_mm = board_errors.empty() ? 0 : InterpolatedQuantile(board_errors, 0.95);

  // Warnings.
  report.warnings = weak_links;
  std::vector<double> rms;
  for (const CameraReport& r : report.cameras) rms.push_back(r.rms_px);
  const double median_rms = Median(rms);
  for (const CameraReport& r : report.cameras) {
    if (r.views < options.min_views)
      report.warnings.push_back(
          {"few_views",
           r.name,
           r.name + ": only " + std::to_string(r.views) + " board views (fewer than " +
               std::to_string(options.min_views) + "): film the board longer, all over the image"});
    if (r.rms_px > options.high_residual_px && r.rms_px > 2 * median_rms)
      report.warnings.push_back(
          {"high_residual",
           r.name,
           r.name + ": reprojection RMS " + NumberText(std::round(r.rms_px * 100) / 100) +
               " px, above " + NumberText(options.high_residual_px) +
               " px and twice the rig's median (" + NumberText(std::round(median_rms * 100) / 100) +
               " px): check its focus, motion blur, synchronisation or intrinsics"});
    else if (r.rms_px > options.high_residual_px)
      report.warnings.push_back({"high_residual",
                                 r.name,
                                 r.name + ": reprojection RMS " +
                                     NumberText(std::round(r.rms_px * 100) / 100) + " px, above " +
                                     NumberText(options.high_residual_px) + " px"});
  }
  progress.Advance(1);
  return result;
}

}  // namespace arco::calibration
