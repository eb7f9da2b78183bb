// A synthetic rig with exact truth for the calibration's tests and bench: distorted
// cameras on a ring looking at its centre, a board moving through (each frame seen only by
// the cameras it faces), the exact corners projected with seeded Gaussian pixel noise.
// RenderBoardImage draws a frame for the detection bench.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "arco/calibration/board.h"
#include "arco/calibration/rig_calibration.h"
#include "arco/camera/rig.h"
#include "arco/media/image.h"

namespace arco::testing {

struct SyntheticBoardRigOptions {
  int num_cameras = 8;
  double ring_radius_mm = 3000;
  double camera_height_mm = 1800;  // the board moves around z = 1200 mm
  int num_frames = 120;
  double noise_px = 0.1;  // standard deviation of each corner coordinate
  int width = 1920, height = 1080;
  double max_view_angle_deg = 65;  // a camera sees the board within this of its normal
  uint64_t seed = 1;
};

struct SyntheticBoardRig {
  Rig truth;                                         // units mm, world z up
  std::vector<Eigen::Isometry3d> world_from_board;   // per frame
  std::vector<calibration::CameraBoardViews> views;  // per camera (names cam0, cam1, ...)
};

SyntheticBoardRig MakeSyntheticBoardRig(const calibration::BoardSpec& board,
                                        const SyntheticBoardRigOptions& options);

// Draws the board (white margin of one square around the squares) as `camera` sees it, with
// its distortion, on a grey background, supersampled; chessboard only. The rays of every
// sample are computed once, at construction.
class BoardRenderer {
 public:
  BoardRenderer(const calibration::BoardSpec& board, const Camera& camera, int supersample = 2);
  media::Image Render(const Eigen::Isometry3d& world_from_board) const;

 private:
  calibration::BoardSpec board_;
  Camera camera_;
  int supersample_;
  std::vector<Eigen::Vector2f> rays_;  // normalised coordinates per sample, row-major
};

}  // namespace arco::testing
