// Body and both hands in COCO-WholeBody-133 from the frames of one camera, with
// MediaPipe's pose detector, pose landmarker, hand re-crop and hand landmarker
// (docs/detect.md, "The detection method").
//
//   detect::WholeBodyOptions options;          // pose_model, thresholds, num_threads
//   ARCO_ASSIGN_OR_RETURN(detect::WholeBodyTracker tracker,
//                         detect::WholeBodyTracker::Create(options));
//   for (each frame of one camera, in order) {
//     ARCO_ASSIGN_OR_RETURN(detect::WholeBodyFrame out, tracker.Track(frame));
//     out.points[p] = {x_px, y_px, score}, p < wholebody::kNumPoints
//   }
//   tracker.summary();                         // counts and timings
//
// Per frame: the pose landmarker runs in the ROI carried from the previous frame's
// landmarks; on the first frame, after Reset(), and when the pose presence falls below
// min_pose_presence, the person detector runs first (the whole frame, then squares of
// it when that finds nobody; the same frame is then tracked from the detection). Hand ROIs come
// from the pose's wrist, index and little-finger points, refined by hand_recrop, and the hand
// landmarker runs on both. Left and right come from the pose (the person's left is COCO's left),
// never from the hand model's handedness output.
//
// Output: pixels of the given image in OpenCV's convention (origin at the centre of the
// top-left pixel); NaN x, y and score where nothing was found: every point of a frame
// without a person, a hand below min_hand_presence, and always the 68 face points and
// the two small toes, which MediaPipe does not give (wholebody_mapping.h). Scores in
// [0, 1]: a body point's is min(visibility, presence), the pose model's two per-point
// sigmoids (in the frame, and not occluded); a hand point's is the hand's presence (the
// hand model gives no per-point confidence). Body points stay even when their score is
// low (an occluded elbow is still estimated): filter by score downstream.
//
// Determinism: the output depends only on the frames since creation or the last Reset,
// in order, bit for bit the same for any num_threads (cv::dnn is bit-exact across thread
// counts; everything else here is sequential). To process a video in parallel, cut it
// into fixed-size chunks, give each worker its own tracker and call Reset() at each
// chunk's first frame: chunk boundaries must then depend on the chunk size only, never
// on the number of threads, or the output would. A tracker is not thread-safe; trackers
// are independent of each other. OpenCV's thread pool is process-wide (network.h): run
// several trackers in parallel with num_threads = 1 each.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>

#include "arco/detect/model_registry.h"
#include "arco/detect/network.h"
#include "arco/detect/roi.h"
#include "arco/media/image.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/util/number_range.h"
#include "arco/util/status.h"

namespace arco::detect {

// The pose landmark model's size: lite / full / heavy (about 11 / 17 / 58 ms per frame).
enum class PoseModel { kLite, kFull, kHeavy };
const char* PoseModelName(PoseModel model);  // "lite", "full", "heavy"
// "lite" | "full" | "heavy"; an error listing them otherwise.
StatusOr<PoseModel> ParsePoseModel(const std::string& name);
ModelId PoseLandmarkModel(PoseModel model);

// The hand landmark model's size: lite / full (about 10 / 16 ms per hand on a quiet
// 2-core machine, docs/performance.md).
enum class HandModel { kLite, kFull };
const char* HandModelName(HandModel model);  // "lite", "full"
// "lite" | "full"; an error listing them otherwise.
StatusOr<HandModel> ParseHandModel(const std::string& name);
ModelId HandLandmarkModel(HandModel model);

// Declared ranges of WholeBodyOptions' numbers (util/number_range.h).
inline constexpr NumberRange kWholeBodyScoreRange = Closed(0, 1);  // thresholds on scores
inline constexpr NumberRange kWholeBodyThreadsRange = Closed(1, 1024);
inline constexpr NumberRange kWholeBodyTileLevelsRange = Closed(0, 2);
// hand_reuse_max_change: 8-bit levels (mean absolute difference of a block of the crop).
inline constexpr NumberRange kWholeBodyHandReuseChangeRange = Closed(0, 16);
// The side of the square blocks of the hand crop compared for hand_reuse_max_change
// (crop pixels; 224 / 16 = 14 x 14 blocks, a finger is about one block wide).
inline constexpr int kHandReuseBlockPx = 16;

struct WholeBodyOptions {
  PoseModel pose_model = PoseModel::kFull;
  HandModel hand_model = HandModel::kFull;
  std::string models_dir;  // empty: DefaultModelsDir()
  // pose_detection: detections below this score are ignored (MediaPipe's 0.5).
  double min_detection_score = 0.5;
  // Weighted NMS merges detections overlapping the best one by more than this IoU.
  double nms_min_iou = 0.3;
  // The detector sees the frame letterboxed into 224 x 224 and misses a person smaller
  // than about a quarter of the frame's longer side. When it finds nobody, level k
  // (1..detection_tile_levels) searches squares of side longer_side / 2^k overlapping by
  // half (level 1: 6 squares of a 4:3 frame; level 2: 35), finest last; the best
  // detection of the first level that finds one wins. 0: whole frame only (MediaPipe).
  // Costs only frames where nobody is tracked and the whole frame finds nobody.
  int detection_tile_levels = 1;
  // Tracking is lost (and the detector runs) when the pose presence is below this.
  double min_pose_presence = 0.5;
  // A hand whose presence is below this is NaN.
  double min_hand_presence = 0.5;
  // Refine the pose-derived hand ROI with hand_recrop (as MediaPipe Holistic); false:
  // the hand landmarker sees a square of 4 wrist-to-middle-finger lengths around the
  // pose's estimate of the middle finger's base.
  bool hand_recrop = true;
  // Hand tracking (MediaPipe's hand tracking graph, hand_landmark_landmarks_to_roi): a
  // hand found on the previous frame with presence >= this gets its crop from its own
  // landmarks (roi.h HandRoiFromLandmarks) instead of from the pose and hand_recrop, as
  // long as that crop lies on this frame's pose hand (centre within 2 wrist-to-middle
  // lengths of the pose's middle-finger base, side between 1 and 8 of them; else the
  // pose's crop, as without tracking). Left and right still come from the pose.
  bool hand_tracking = false;
  double min_hand_tracking_presence = 0.5;
  // A still hand: when the crop the hand landmarker saw on an earlier frame, cut again
  // from this frame at the same place, differs from it by at most this (the largest mean
  // absolute difference, in 8-bit levels, over blocks of kHandReuseBlockPx x
  // kHandReuseBlockPx crop pixels), the hand landmarker is skipped and that frame's hand
  // (points and presence) is used again. Blocks, not the whole crop, so that one finger
  // moving is seen. The reference crop stays the one last landmarked, so slow drift
  // adds up until it is run again. 0: always run the landmarker.
  double hand_reuse_max_change = 0;
  int num_threads = 1;  // threads of one forward pass (network.h)
  // Which runtime runs the models (network.h): XNNPACK where a model's graph translates.
  InferenceRuntime runtime = InferenceRuntime::kAuto;
  // Every number inside its declared range; messages name the field.
  Status Validate() const;
};

struct ScoredPoint {
  float x_px = std::numeric_limits<float>::quiet_NaN();
  float y_px = std::numeric_limits<float>::quiet_NaN();
  float score = std::numeric_limits<float>::quiet_NaN();
};
// WholeBodyFrame::points is laid out as float[kNumPoints][3] (x, y, score): one row of
// keypoints2d.npy (docs/formats.md), copyable as is.
static_assert(sizeof(ScoredPoint) == 3 * sizeof(float), "ScoredPoint must be 3 packed floats");

struct WholeBodyFrame {
  std::array<ScoredPoint, wholebody::kNumPoints> points;  // COCO-WholeBody order
  bool person = false;                                    // pose presence >= min_pose_presence
  bool left_hand = false;   // the person's left hand, points kLeftHandFirst..
  bool right_hand = false;  // points kRightHandFirst..
  bool detector_ran = false;
  // The models' presence sigmoids (NaN where the model did not run).
  float pose_presence = std::numeric_limits<float>::quiet_NaN();
  float left_hand_presence = std::numeric_limits<float>::quiet_NaN();
  float right_hand_presence = std::numeric_limits<float>::quiet_NaN();
};

struct WholeBodySummary {
  int64_t frames = 0;
  int64_t frames_with_person = 0;
  int64_t frames_with_left_hand = 0;
  int64_t frames_with_right_hand = 0;
  // Frames on which the person detector ran (models[0].runs counts its passes: the
  // whole frame and any squares searched).
  int64_t detector_runs = 0;
  // Of those, the ones after a person had been found since creation or the last
  // Reset: tracking was lost.
  int64_t redetections = 0;
  // Hands whose crop came from their previous landmarks (hand_tracking), and hands taken
  // again from an earlier frame without running the landmarker (hand_reuse_max_change).
  int64_t hands_tracked = 0;
  int64_t hands_reused = 0;
  // Wall time of the forward passes (Network::Run) per model kind, and of the rest:
  // cutting and converting crops (preprocess), decoding outputs and ROI geometry
  // (postprocess). Not deterministic; never part of the output.
  struct ModelTime {
    ModelId model = ModelId::kPoseDetection;
    const char* runtime = "";  // Network::runtime_name(); "" when not loaded
    int64_t runs = 0;
    double inference_s = 0;
  };
  std::array<ModelTime, 4> models;  // detector, pose landmarks, hand recrop, hand landmarks
  double inference_s = 0;
  double preprocess_s = 0;
  double postprocess_s = 0;

  // Adds another tracker's counts and times (chunks of one video, several cameras).
  void Merge(const WholeBodySummary& other);
};

class WholeBodyTracker {
 public:
  // Validates the options and loads the networks (a missing model file is one line
  // naming it and pointing to scripts/setup).
  static StatusOr<WholeBodyTracker> Create(const WholeBodyOptions& options);

  WholeBodyTracker(WholeBodyTracker&&) noexcept;
  WholeBodyTracker& operator=(WholeBodyTracker&&) noexcept;
  ~WholeBodyTracker();

  // The next frame of the camera: RGB8, at least 2 x 2 pixels (throws
  // std::invalid_argument otherwise). An error only when inference fails.
  StatusOr<WholeBodyFrame> Track(const media::Image& frame);
  // Forgets the tracked person: the next frame starts with detection. Keeps summary().
  void Reset();
  // The hand landmarker alone on `roi` of `frame` (a crop the caller chose, e.g. around a
  // hand triangulated from other views: capture/hand_consistency.h): writes 21 points in
  // hand_21 order from `first`, each scored with the presence (all NaN when the presence
  // is below min_hand_presence), and returns the presence. Neither reads nor changes the
  // tracking state; counted in summary() as a hand landmark run. Same frame checks as
  // Track.
  StatusOr<double> LandmarkHand(const media::Image& frame, const Roi& roi, ScoredPoint* first);

  const WholeBodyOptions& options() const;
  const WholeBodySummary& summary() const;

 private:
  struct Impl;
  explicit WholeBodyTracker(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace arco::detect
