// Stage 0 of a capture made from videos (`arco detect CAPTURE`): the body and both hands
// in every camera's video, as COCO-WholeBody keypoints in the capture's keypoints2d.npy
// (docs/detect.md). The detection itself is detect::WholeBodyTracker (detect/wholebody.h);
// this stage reads the frames through media::VideoReader, turns them into the
// calibration's orientation, runs one tracker per worker over (camera, chunk) items and
// writes the capture's keypoints and manifest together.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "arco/capture/hand_consistency.h"
#include "arco/detect/wholebody.h"
#include "arco/util/json_io.h"
#include "arco/util/number_range.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"

namespace arco::capture {

// Frames per work item. Tracking restarts with person detection at each chunk's first
// frame, so chunk boundaries are a function of this number only (never of the thread
// count): the output is the same for any num_threads.
inline constexpr NumberRange kDetectChunkFramesRange = Closed(1, 100000);

struct DetectStageOptions {
  std::string capture_dir;
  // The models, thresholds and pose model size; its num_threads is ignored (the stage
  // splits num_threads between workers and cv::dnn).
  detect::WholeBodyOptions detector;
  int num_threads = 0;  // 0 = all cores
  // Global frame numbers (capture.json frames.first ...), inclusive; -1 = the capture's
  // first / last frame. Frames outside keep what keypoints2d.npy held (NaN if nothing).
  int64_t first_frame = -1;
  int64_t last_frame = -1;
  int chunk_frames = 150;
  // Read and decode each worker's next frame on a thread of its own while the worker's
  // tracker runs on the current one (one extra thread per worker, mostly waiting). The
  // output is the same either way; false: decode and track in turn, as before issue 28.
  bool decode_ahead = true;
  // Hands checked across the calibrated views after detection (hand_consistency.h):
  // swapped hands exchanged, disagreeing hands re-run on a crop around the hand
  // triangulated from the other views, kept when they then agree, else down-weighted.
  // Skipped for cameras synced by sound (their rows are not simultaneous).
  HandConsistencyOptions hands;
  Status Validate() const;
};

Json ToJson(const DetectStageOptions& options);

struct DetectCameraSummary {
  std::string camera;
  std::string video;    // as resolved
  int64_t frames = 0;   // frames read (dropped frames excluded)
  int64_t dropped = 0;  // frames of the range this camera did not record (NaN)
  detect::WholeBodySummary tracker;
};

struct DetectStageSummary {
  std::string layout;  // of the keypoints written
  int64_t first_frame = 0, last_frame = 0;
  int64_t points = 0;  // per frame and view
  std::vector<DetectCameraSummary> cameras;
  detect::WholeBodySummary total;
  double decode_s = 0;  // reading, decoding and rotating frames (all workers)
  // Of decode_s, what the trackers waited for (the rest overlapped inference: frames
  // are decoded ahead on a thread beside each worker).
  double decode_wait_s = 0;
  double wall_s = 0;
  bool kept_other_points = false;  // instrument/bow slots kept from the old keypoints2d.npy
  HandConsistencySummary hands;    // the check across views
};

Json ToJson(const DetectStageSummary& summary);

// Checks the capture (manifest, every camera's video present, readable and of its
// calibration camera's size after rotate_deg, the models) before any frame is decoded,
// then detects and replaces CAPTURE/keypoints2d.npy, capture.json and detect.json (the
// options as applied and the counts of the summary, without times) together
// (util/output_set.h): on any error none changes. Progress: total = frames x cameras.
StatusOr<DetectStageSummary> RunDetectStage(const DetectStageOptions& options,
                                            Progress& progress = NoProgress());

}  // namespace arco::capture
