// Calibrating a camera rig from board detections (`arco calibrate`, docs/calibration.md
// "Calibrating a rig"):
//   1. intrinsics per camera: OpenCV's calibrateCamera (Zhang 2000) on up to
//      max_intrinsic_views views chosen to cover the image, expressed in arco's model
//      (camera/camera.h: fx fy cx cy, skew 0, k1 k2 k3 p1 p2), unless given;
//   2. board pose in every view (PnP);
//   3. relative poses of camera pairs from the frames in which both see the board
//      (consensus of the per-frame estimates, then their mean), chained from the root camera
//      over a maximum spanning tree of the camera graph (edge weight = shared frames);
//   4. one bundle adjustment in Ceres over every camera pose and every board pose (one per
//      frame), Huber loss, intrinsics refined unless fixed; residuals through arco's
//      templated model (PixelFromPointInCamera).
// Units: mm (the board's square size gives the metric scale). World frame: the origin
// camera (default the first) or the board of the first frame that two cameras see.
// Pixels: OpenCV convention (origin at the centre of the top-left pixel), as everywhere.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "arco/calibration/board.h"
#include "arco/calibration/bundle_adjustment.h"
#include "arco/camera/rig.h"
#include "arco/util/number_range.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"

namespace arco::calibration {

// One board detected in one frame of one camera.
struct BoardView {
  int64_t frame = 0;                        // frame index, shared by all cameras (synchronised)
  std::vector<int> point_ids;               // into BoardSpec::PointsInBoard()
  std::vector<Eigen::Vector2d> corners_px;  // same order
};

// Every board a camera saw.
struct CameraBoardViews {
  std::string camera;  // camera name (unique in the rig)
  std::string source;  // the video or folder, for messages
  int width = 0, height = 0;
  int64_t frames_read = 0;
  std::vector<BoardView> views;  // by increasing frame
};

inline constexpr NumberRange kIntrinsicViewsRange = Closed(3, 10000);
inline constexpr NumberRange kLossScaleRangePx = AboveZero(1000);
inline constexpr NumberRange kIterationsRange = Closed(1, 100000);
inline constexpr NumberRange kHighResidualRangePx = AboveZero(1000);
inline constexpr NumberRange kMinViewsRange = Closed(1, 100000);

struct RigCalibrationOptions {
  bool refine_intrinsics = true;  // false: the intrinsics stay as initialised (or given)
  std::string origin;             // "" (the first camera), a camera name, or "board"
  int max_intrinsic_views = 40;   // views per camera for calibrateCamera, covering the image
  double loss_scale_px = 2.0;     // Huber loss: quadratic up to this residual
  int max_iterations = 200;       // bundle adjustment iterations
  double high_residual_px = 1.0;  // warning "high_residual" above this RMS
  int min_views = 10;             // warning "few_views" below this many views of a camera
  Status Validate() const;        // messages name the fields
};

struct CameraReport {
  std::string name;
  int views = 0;         // frames in which the board was detected
  int views_used = 0;    // views in the bundle adjustment
  int observations = 0;  // corners in the bundle adjustment
  double rms_px = 0;     // reprojection error after the bundle adjustment
  double p95_px = 0;
  bool intrinsics_given = false;
};

struct PairReport {
  std::string camera_a, camera_b;
  int shared_frames = 0;
};

// A named condition the user should know about ("few_views", "high_residual").
struct CalibrationWarning {
  std::string code;
  std::string camera;
  std::string message;
};

struct RigCalibrationReport {
  std::string board;   // BoardSpec::ToString()
  std::string origin;  // the world frame: a camera name or "board@FRAME"
  std::vector<CameraReport> cameras;
  std::vector<PairReport> pairs;  // every pair with at least one shared frame
  double rms_px = 0;              // over all cameras
  // Board corners triangulated from every frame seen by two or more cameras, compared
  // with the board's geometry after a rigid fit per frame (mm).
  int board_points = 0;
  double board_rms_mm = 0, board_p95_mm = 0;
  BundleAdjustmentSummary bundle_adjustment;
  std::vector<CalibrationWarning> warnings;
  nlohmann::ordered_json ToJson() const;
};

struct RigCalibration {
  Rig rig;  // units "mm", cameras in the order of the input
  RigCalibrationReport report;
};

// `initial` (may be null) gives intrinsics for the cameras it names (by name); the others
// are calibrated from their views. Errors: fewer than two cameras, a camera without views
// or whose intrinsics cannot be estimated, a camera graph that is not connected (the
// message lists the groups), an unknown origin. Throws std::invalid_argument on invalid
// options or views whose ids and corners differ in size (caller bugs).
StatusOr<RigCalibration> CalibrateRig(const RigCalibrationOptions& options,
                                      const BoardSpec& board,
                                      const std::vector<CameraBoardViews>& cameras,
                                      const Rig* initial = nullptr,
                                      Progress& progress = NoProgress());

}  // namespace arco::calibration
