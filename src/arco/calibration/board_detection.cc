#include "arco/calibration/board_detection.h"

#include <algorithm>
#include <cmath>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "arco/media/video_reader.h"

namespace arco::calibration {
namespace {

cv::Mat GrayMat(const media::Image& image, cv::Mat* storage) {
  const cv::Mat wrapped(image.height,
                        image.width,
                        image.format == media::PixelFormat::kGray8 ? CV_8UC1 : CV_8UC3,
                        const_cast<uint8_t*>(image.pixels.data()));
  if (image.format == media::PixelFormat::kGray8) return wrapped;
  cv::cvtColor(wrapped, *storage, cv::COLOR_RGB2GRAY);
  return *storage;
}

// Half-size of the corner refinement window: under half the smallest corner spacing, so
// the window stays inside the squares around a corner.
int RefineWindow(const std::vector<cv::Point2f>& corners, int cols) {
  double spacing = 1e9;
  for (size_t i = 0; i + 1 < corners.size(); ++i)
    if (static_cast<int>((i + 1) % cols) != 0)
      spacing = std::min(spacing, static_cast<double>(cv::norm(corners[i + 1] - corners[i])));
  return std::clamp(static_cast<int>(spacing * 0.4), 2, 11);
}

int CharucoDictionaryId(const std::string& name) {
  const std::vector<std::string>& names = CharucoDictionaryNames();
  // The names are listed in OpenCV's PREDEFINED_DICTIONARY_NAME order.
  return static_cast<int>(std::find(names.begin(), names.end(), name) - names.begin());
}

}  // namespace

Status BoardDetectionOptions::Validate() const {
  ARCO_RETURN_IF_ERROR(CheckInRange("frame_step", frame_step, kFrameStepRange));
  ARCO_RETURN_IF_ERROR(
      CheckInRange("max_frames", static_cast<double>(max_frames), kMaxFramesRange));
  ARCO_RETURN_IF_ERROR(CheckInRange("search_max_side", search_max_side, Closed(0, 100000)));
  return Status::Ok();
}

std::optional<BoardView> DetectBoard(const BoardSpec& board,
                                     const media::Image& image,
                                     const BoardDetectionOptions& options) {
  if (image.empty()) return std::nullopt;
  cv::Mat storage;
  const cv::Mat gray = GrayMat(image, &storage);
  const int side = std::max(gray.cols, gray.rows);
  const double scale = options.search_max_side > 0 && side > options.search_max_side
                           ? static_cast<double>(options.search_max_side) / side
                           : 1.0;
  cv::Mat search = gray;
  if (scale < 1) cv::resize(gray, search, cv::Size(), scale, scale, cv::INTER_AREA);

  BoardView view;
  if (board.kind == BoardKind::kChessboard) {
    std::vector<cv::Point2f> corners;
    const cv::Size pattern(board.inner_cols, board.inner_rows);
    const int flags =
        cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK;
    if (!cv::findChessboardCorners(search, pattern, corners, flags)) return std::nullopt;
    if (static_cast<int>(corners.size()) != board.num_points()) return std::nullopt;
    // Pixel centres: a corner at p in the scaled image is at (p + 0.5) / scale - 0.5.
    for (auto& c : corners) c = (c + cv::Point2f(0.5f, 0.5f)) / scale - cv::Point2f(0.5f, 0.5f);
    const int w = RefineWindow(corners, board.inner_cols);
    cv::cornerSubPix(gray,
                     corners,
                     cv::Size(w, w),
                     cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-3));
    for (int i = 0; i < static_cast<int>(corners.size()); ++i) {
      view.point_ids.push_back(i);
      view.corners_px.emplace_back(corners[i].x, corners[i].y);
    }
    return view;
  }

  const cv::Ptr<cv::aruco::Dictionary> dictionary =
      cv::aruco::getPredefinedDictionary(CharucoDictionaryId(board.dictionary));
  const cv::Ptr<cv::aruco::CharucoBoard> charuco =
      cv::aruco::CharucoBoard::create(board.inner_cols + 1,
                                      board.inner_rows + 1,
                                      static_cast<float>(board.square_mm),
                                      static_cast<float>(board.marker_mm),
                                      dictionary);
  std::vector<std::vector<cv::Point2f>> marker_corners;
  std::vector<int> marker_ids;
  cv::aruco::detectMarkers(search, dictionary, marker_corners, marker_ids);
  if (marker_ids.empty()) return std::nullopt;
  for (auto& marker : marker_corners)
    for (auto& c : marker) c = (c + cv::Point2f(0.5f, 0.5f)) / scale - cv::Point2f(0.5f, 0.5f);
  std::vector<cv::Point2f> corners;
  std::vector<int> ids;
  // Interpolated from the markers and refined (cornerSubPix) on the full-resolution image.
  cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, gray, charuco, corners, ids);
  if (ids.size() < 6) return std::nullopt;
  for (size_t i = 0; i < ids.size(); ++i) {
    view.point_ids.push_back(ids[i]);
    view.corners_px.emplace_back(corners[i].x, corners[i].y);
  }
  return view;
}

StatusOr<CameraBoardViews> DetectBoardInVideo(const BoardSpec& board,
                                              const std::string& camera,
                                              const std::string& path,
                                              const BoardDetectionOptions& options,
                                              Progress& progress) {
  media::VideoReaderOptions reader_options;
  reader_options.format = media::PixelFormat::kGray8;
  ARCO_ASSIGN_OR_RETURN(media::VideoReader reader, media::VideoReader::Open(path, reader_options));
  CameraBoardViews result;
  result.camera = camera;
  result.source = path;
  result.width = reader.properties().width;
  result.height = reader.properties().height;
  int64_t total = reader.properties().frame_count / options.frame_step;
  if (options.max_frames > 0) total = std::min(total, options.max_frames);
  progress.SetTotal(total);
  media::Image frame;
  for (int64_t index = 0;; ++index) {
    if (options.max_frames > 0 && result.frames_read >= options.max_frames) break;
    ARCO_ASSIGN_OR_RETURN(bool more, reader.Read(&frame));
    if (!more) break;
    if (index % options.frame_step != 0) continue;
    if (frame.width != result.width || frame.height != result.height)
      return Status::Error(path + ": frame " + std::to_string(index) + " is " +
                           std::to_string(frame.width) + "x" + std::to_string(frame.height) +
                           ", the first is " + std::to_string(result.width) + "x" +
                           std::to_string(result.height));
    ++result.frames_read;
    if (auto view = DetectBoard(board, frame, options)) {
      view->frame = index;
      result.views.push_back(std::move(*view));
    }
    progress.Advance(1);
  }
  return result;
}

}  // namespace arco::calibration
