// Board detection in images and videos (OpenCV, privately): a chessboard's inner corners
// (findChessboardCorners, then cornerSubPix) or a ChArUco board's corners (ArUco markers,
// then the corners interpolated between them). Corners are in pixels, OpenCV's convention
// (origin at the centre of the top-left pixel), ids as in board.h.
#pragma once

#include <optional>
#include <string>

#include "arco/calibration/board.h"
#include "arco/calibration/rig_calibration.h"
#include "arco/media/image.h"
#include "arco/util/number_range.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"

namespace arco::calibration {

inline constexpr NumberRange kFrameStepRange = Closed(1, 1e6);
inline constexpr NumberRange kMaxFramesRange = Closed(0, 1e9);

struct BoardDetectionOptions {
  int frame_step = 1;      // look at every frame_step-th frame (0, step, 2 step, ...)
  int64_t max_frames = 0;  // > 0: at most this many frames looked at per camera
  // Largest image side the corner search runs on (the frame is scaled down for the search,
  // the corners refined at full resolution); 0: full size.
  int search_max_side = 1280;
  Status Validate() const;
};

// The board in one frame (any PixelFormat); nullopt when it is not found. The view's
// `frame` is left 0. A ChArUco view needs at least 6 corners.
std::optional<BoardView> DetectBoard(const BoardSpec& board,
                                     const media::Image& image,
                                     const BoardDetectionOptions& options = {});

// Every frame of a video, an image folder or a single image (media::VideoReader).
// Errors: the file cannot be read (its message begins with the path).
StatusOr<CameraBoardViews> DetectBoardInVideo(const BoardSpec& board,
                                              const std::string& camera,
                                              const std::string& path,
                                              const BoardDetectionOptions& options = {},
                                              Progress& progress = NoProgress());

}  // namespace arco::calibration
