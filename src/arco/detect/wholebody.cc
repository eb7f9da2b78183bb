#include "arco/detect/wholebody.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include "arco/detect/network.h"
#include "arco/detect/roi.h"
#include "arco/detect/ssd.h"
#include "arco/detect/wholebody_mapping.h"

namespace arco::detect {
namespace {

constexpr double kPi = 3.14159265358979323846;
// MediaPipe's graph constants (pose_detection_to_roi, pose_landmarks_to_roi,
// hand_landmarks_from_pose_to_recrop_roi, hand_recrop_by_roi).
constexpr double kPoseRoiScale = 1.25;
constexpr double kHandRecropRoiScale = 2.7;
constexpr double kHandRecropRoiShiftY = -0.1;
constexpr double kHandRoiFromRecropShiftY = -0.1;
// Without hand_recrop: a square of 4 wrist-to-middle lengths centred on the middle
// finger's base (network_test.cc: presence 0.99 on the cellist's left hand).
constexpr double kHandRoiFallbackScale = 2.0;
// A ROI smaller than this (image pixels) holds nothing the models can see.
constexpr double kMinRoiSidePx = 8.0;
constexpr int kNumHandLandmarks = 21;

enum ModelSlot { kDetectorSlot = 0, kPoseSlot = 1, kRecropSlot = 2, kHandSlot = 3 };

using Clock = std::chrono::steady_clock;
double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

double Sigmoid(double x) { return 1.0 / (1.0 + std::exp(-x)); }

bool InsideImage(Point2 p, int width, int height) {
  return p.x >= -0.5 && p.y >= -0.5 && p.x <= width - 0.5 && p.y <= height - 0.5;
}

void SetPoint(ScoredPoint* point, Point2 p, double score) {
  point->x_px = static_cast<float>(p.x);
  point->y_px = static_cast<float>(p.y);
  point->score = static_cast<float>(score);
}

}  // namespace

const char* PoseModelName(PoseModel model) {
  switch (model) {
    case PoseModel::kLite:
      return "lite";
    case PoseModel::kFull:
      return "full";
    case PoseModel::kHeavy:
      return "heavy";
  }
  return "?";
}

StatusOr<PoseModel> ParsePoseModel(const std::string& name) {
  for (PoseModel model : {PoseModel::kLite, PoseModel::kFull, PoseModel::kHeavy}) {
    if (name == PoseModelName(model)) return model;
  }
  return Status::Error("unknown pose model '" + name + "' (lite, full or heavy)");
}

const char* HandModelName(HandModel model) {
  return model == HandModel::kLite ? "lite" : "full";
}

StatusOr<HandModel> ParseHandModel(const std::string& name) {
  if (name == "lite") return HandModel::kLite;
  if (name == "full") return HandModel::kFull;
  return Status::Error("unknown hand model \"" + name + "\" (lite, full)");
}

ModelId HandLandmarkModel(HandModel model) {
  return model == HandModel::kLite ? ModelId::kHandLandmarkLite : ModelId::kHandLandmarkFull;
}

ModelId PoseLandmarkModel(PoseModel model) {
  switch (model) {
    case PoseModel::kLite:
      return ModelId::kPoseLandmarkLite;
    case PoseModel::kHeavy:
      return ModelId::kPoseLandmarkHeavy;
    case PoseModel::kFull:
      break;
  }
  return ModelId::kPoseLandmarkFull;
}

Status WholeBodyOptions::Validate() const {
  if (pose_model != PoseModel::kLite && pose_model != PoseModel::kFull &&
      pose_model != PoseModel::kHeavy) {
    return Status::Error("WholeBodyOptions.pose_model must be lite, full or heavy");
  }
  if (hand_model != HandModel::kLite && hand_model != HandModel::kFull) {
    return Status::Error("WholeBodyOptions.hand_model must be lite or full");
  }
  ARCO_RETURN_IF_ERROR(CheckInRange(
      "WholeBodyOptions.min_detection_score", min_detection_score, kWholeBodyScoreRange));
  ARCO_RETURN_IF_ERROR(
      CheckInRange("WholeBodyOptions.nms_min_iou", nms_min_iou, kWholeBodyScoreRange));
  ARCO_RETURN_IF_ERROR(
      CheckInRange("WholeBodyOptions.min_pose_presence", min_pose_presence, kWholeBodyScoreRange));
  ARCO_RETURN_IF_ERROR(
      CheckInRange("WholeBodyOptions.min_hand_presence", min_hand_presence, kWholeBodyScoreRange));
  ARCO_RETURN_IF_ERROR(
      CheckInRange("WholeBodyOptions.num_threads", num_threads, kWholeBodyThreadsRange));
  ARCO_RETURN_IF_ERROR(CheckInRange(
      "WholeBodyOptions.detection_tile_levels", detection_tile_levels, kWholeBodyTileLevelsRange));
  ARCO_RETURN_IF_ERROR(CheckInRange("WholeBodyOptions.min_hand_tracking_presence",
                                    min_hand_tracking_presence,
                                    kWholeBodyScoreRange));
  ARCO_RETURN_IF_ERROR(CheckInRange("WholeBodyOptions.hand_reuse_max_change",
                                    hand_reuse_max_change,
                                    kWholeBodyHandReuseChangeRange));
  return Status::Ok();
}

void WholeBodySummary::Merge(const WholeBodySummary& other) {
  frames += other.frames;
  frames_with_person += other.frames_with_person;
  frames_with_left_hand += other.frames_with_left_hand;
  frames_with_right_hand += other.frames_with_right_hand;
  detector_runs += other.detector_runs;
  redetections += other.redetections;
  hands_tracked += other.hands_tracked;
  hands_reused += other.hands_reused;
  for (size_t k = 0; k < models.size(); ++k) {
    if (*models[k].runtime == '\0') {  // a summary that has loaded nothing yet (a total)
      models[k].model = other.models[k].model;
      models[k].runtime = other.models[k].runtime;
    }
    models[k].runs += other.models[k].runs;
    models[k].inference_s += other.models[k].inference_s;
  }
  inference_s += other.inference_s;
  preprocess_s += other.preprocess_s;
  postprocess_s += other.postprocess_s;
}

struct WholeBodyTracker::Impl {
  WholeBodyOptions options;
  std::array<std::optional<Network>, 4> networks;  // by ModelSlot; no recrop without it
  std::array<std::vector<float>, 4> inputs;        // one NHWC float input per network
  cv::Mat crop;                                    // the 8-bit crop being cut
  WholeBodySummary summary;
  // Tracking state (all of it: Reset clears it).
  bool tracking = false;
  Roi pose_roi;
  bool person_seen = false;  // since creation or Reset: later detector runs re-detect
  // Per-frame scratch, allocated once.
  std::vector<SsdDetection> detections;
  std::array<Point2, mediapipe_pose::kNumWithAuxiliary> pose_points{};
  std::array<double, mediapipe_pose::kNumWithAuxiliary> pose_scores{};
  std::array<Point2, kNumHandLandmarks> hand_points{};  // HandInRoi's, image pixels
  cv::Mat reuse_crop;  // the crop cut again to compare (hand_reuse_max_change)
  // Per hand (0: the person's left, 1: right), what the last frame found: hand tracking
  // and re-use start from it. Cleared by Reset and whenever the hand is not found.
  struct HandState {
    bool found = false;  // the last frame's hand reached min_hand_presence
    double presence = 0;
    std::array<ScoredPoint, kNumHandLandmarks> points{};  // as written to the frame
    std::array<Point2, kNumHandLandmarks> landmarks{};    // the same, in double
    // The crop the landmarker last saw and its 8-bit pixels (hand_reuse_max_change > 0).
    Roi landmarked_roi;
    cv::Mat landmarked_crop;
  };
  std::array<HandState, 2> hand_state;

  // Cuts `roi` of `image` as a size x size 8-bit crop into `out` (bilinear, black outside).
  static void WarpCrop(const cv::Mat& image, const Roi& roi, int size, cv::Mat* out) {
    double m[6];
    roi.CropPixelToImageAffine(size, m);
    const cv::Mat to_image(2, 3, CV_64F, m);
    cv::warpAffine(image,
                   *out,
                   to_image,
                   cv::Size(size, size),
                   cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                   cv::BORDER_CONSTANT,
                   cv::Scalar::all(0));
  }

  // Cuts `roi` from `image` into slot's input (its size and value range), straight into
  // the network's planar layout (NCHW): the values are those of the interleaved input
  // Network::Run would otherwise reorder, without that extra pass.
  void CutCrop(const cv::Mat& image, const Roi& roi, ModelSlot slot) {
    const auto start = Clock::now();
    const ModelInfo& info = networks[slot]->info();
    const int size = info.input_width;
    WarpCrop(image, roi, size, &crop);
    std::vector<float>& input = inputs[slot];
    const float scale = info.range == ValueRange::kZeroToOne ? 1.0f / 255.0f : 1.0f / 127.5f;
    const float offset = info.range == ValueRange::kZeroToOne ? 0.0f : -1.0f;
    const size_t plane = static_cast<size_t>(size) * size;
    float* r = input.data();
    float* g = r + plane;
    float* b = g + plane;
    for (int y = 0; y < size; ++y) {
      const uint8_t* row = crop.ptr<uint8_t>(y);
      const size_t at = static_cast<size_t>(y) * size;
      for (int x = 0; x < size; ++x) {
        r[at + x] = row[3 * x] * scale + offset;
        g[at + x] = row[3 * x + 1] * scale + offset;
        b[at + x] = row[3 * x + 2] * scale + offset;
      }
    }
    summary.preprocess_s += Seconds(start);
  }

  Status Run(ModelSlot slot) {
    const auto start = Clock::now();
    ARCO_RETURN_IF_ERROR(
        networks[slot]->Run(inputs[slot].data(), inputs[slot].size(), TensorLayout::kNchw));
    const double s = Seconds(start);
    summary.models[slot].runs += 1;
    summary.models[slot].inference_s += s;
    summary.inference_s += s;
    return Status::Ok();
  }

  // The best detection in `region` (a square of the image, upright) whose score beats
  // *best_score: its keypoints 0 (hip centre) and 1 (full-body circle) in the image.
  Status DetectIn(
      const cv::Mat& image, const Roi& region, double* best_score, Point2* hip, Point2* circle) {
    CutCrop(image, region, kDetectorSlot);
    ARCO_RETURN_IF_ERROR(Run(kDetectorSlot));
    const auto start = Clock::now();
    const Network& net = *networks[kDetectorSlot];
    detections = DecodeSsd(net.output("boxes").data.data(),
                           net.output("scores").data.data(),
                           PoseDetectionAnchors(),
                           kPoseDetectionKeypoints,
                           kPoseDetectionInputSize,
                           options.min_detection_score);
    detections = WeightedNonMaxSuppression(std::move(detections), options.nms_min_iou);
    if (!detections.empty() && detections.front().score > *best_score) {
      const SsdDetection& best = detections.front();
      *best_score = best.score;
      *hip = region.ToImage(best.keypoints[0].x, best.keypoints[0].y);
      *circle = region.ToImage(best.keypoints[1].x, best.keypoints[1].y);
    }
    summary.postprocess_s += Seconds(start);
    return Status::Ok();
  }

  // The best person, as the pose ROI of its keypoints; false when no detection reaches
  // min_detection_score. The whole frame first, then the tile levels (see
  // WholeBodyOptions::detection_tile_levels), in a fixed order.
  StatusOr<bool> Detect(const cv::Mat& image, Roi* roi) {
    double best_score = -1;
    Point2 hip, circle;
    ARCO_RETURN_IF_ERROR(
        DetectIn(image, WholeImageRoi(image.cols, image.rows), &best_score, &hip, &circle));
    const int longer = std::max(image.cols, image.rows);
    for (int level = 1; level <= options.detection_tile_levels && best_score < 0; ++level) {
      const int side = longer >> level;
      if (side < kPoseDetectionInputSize / 2) break;  // tiles this small upscale too much
      // Tile origins every side / 2, the last one flush with the image's far edge.
      auto origins = [&](int extent) {
        std::vector<int> starts;
        if (extent <= side) return std::vector<int>{(extent - side) / 2};
        for (int o = 0; o + side < extent; o += side / 2) starts.push_back(o);
        starts.push_back(extent - side);
        return starts;
      };
      for (int y0 : origins(image.rows)) {
        for (int x0 : origins(image.cols)) {
          Roi tile;
          tile.centre = {x0 + (side - 1) / 2.0, y0 + (side - 1) / 2.0};
          tile.side_px = side;
          ARCO_RETURN_IF_ERROR(DetectIn(image, tile, &best_score, &hip, &circle));
        }
      }
    }
    if (best_score < 0) return false;
    *roi = RoiFromAlignmentPoints(hip, circle, kPi / 2, kPoseRoiScale);
    return roi->IsFinite() && roi->side_px >= kMinRoiSidePx;
  }

  // Pose landmarks in `roi` into pose_points / pose_scores; returns the presence.
  StatusOr<double> PoseLandmarks(const cv::Mat& image, const Roi& roi) {
    CutCrop(image, roi, kPoseSlot);
    ARCO_RETURN_IF_ERROR(Run(kPoseSlot));
    const auto start = Clock::now();
    const Network& net = *networks[kPoseSlot];
    const int size = net.info().input_width;
    const std::vector<float>& raw = net.output("landmarks").data;
    for (int i = 0; i < mediapipe_pose::kNumWithAuxiliary; ++i) {
      const float* p = &raw[5 * i];
      pose_points[i] = roi.CropPixelToImage(p[0], p[1], size);
      pose_scores[i] = std::min(Sigmoid(p[3]), Sigmoid(p[4]));
    }
    const double presence = net.output("presence").data[0];
    summary.postprocess_s += Seconds(start);
    return presence;
  }

  // One hand from the pose's wrist, index and little-finger points: writes 21 points
  // from `first` and returns the presence (NaN when the hand was not looked for).
  // `side` 0 is the person's left hand, 1 the right (hand_state).
  StatusOr<double> Hand(const cv::Mat& image,
                        int side,
                        int wrist_index,
                        int index_index,
                        int pinky_index,
                        ScoredPoint* first) {
    const auto start = Clock::now();
    HandState& state = hand_state[side];
    const Point2 wrist = pose_points[wrist_index];
    const Point2 index = pose_points[index_index], pinky = pose_points[pinky_index];
    const Point2 middle = (1.0 / 3.0) * (2.0 * index + pinky);
    const double length = Norm(middle - wrist);
    summary.postprocess_s += Seconds(start);
    if (!(length * 4 >= kMinRoiSidePx) || !InsideImage(middle, image.cols, image.rows)) {
      state.found = false;
      return std::numeric_limits<double>::quiet_NaN();
    }
    // A crop for this hand is kept only when it lies on the pose's hand.
    const auto on_pose_hand = [&](const Roi& r) {
      return r.IsFinite() && Norm(r.centre - middle) < 2 * length && r.side_px > length &&
             r.side_px < 8 * length;
    };
    if (options.hand_reuse_max_change > 0 && state.found && !state.landmarked_crop.empty() &&
        StillSince(image, state)) {
      std::copy(state.points.begin(), state.points.end(), first);
      summary.hands_reused += 1;
      return state.presence;
    }
    Roi roi;
    bool tracked = false;
    if (options.hand_tracking && state.found &&
        state.presence >= options.min_hand_tracking_presence) {
      const auto from_landmarks = Clock::now();
      const std::optional<Roi> next =
          HandRoiFromLandmarks(state.landmarks.data(), kHandTrackingRoiPoints);
      if (next && on_pose_hand(*next)) {
        roi = *next;
        tracked = true;
        summary.hands_tracked += 1;
      }
      summary.postprocess_s += Seconds(from_landmarks);
    }
    if (!tracked) {
      ARCO_ASSIGN_OR_RETURN(roi, RoiFromPose(image, wrist, index, pinky, on_pose_hand));
    }
    ARCO_ASSIGN_OR_RETURN(const double presence, HandInRoi(image, roi, first));
    state.found = presence >= options.min_hand_presence;
    if (state.found) {
      state.presence = presence;
      std::copy(first, first + kNumHandLandmarks, state.points.begin());
      state.landmarks = hand_points;
      if (options.hand_reuse_max_change > 0) {
        state.landmarked_roi = roi;
        crop.copyTo(state.landmarked_crop);  // HandInRoi's crop
      }
    }
    return presence;
  }

  // Whether the pixels under the crop the landmarker last saw for this hand are still
  // what it saw (hand_reuse_max_change, kHandReuseBlockPx).
  bool StillSince(const cv::Mat& image, const HandState& state) {
    const auto start = Clock::now();
    const int size = state.landmarked_crop.rows;
    WarpCrop(image, state.landmarked_roi, size, &reuse_crop);
    const double max_sum = options.hand_reuse_max_change;
    bool still = true;
    for (int by = 0; by < size && still; by += kHandReuseBlockPx) {
      for (int bx = 0; bx < size && still; bx += kHandReuseBlockPx) {
        const int y_end = std::min(size, by + kHandReuseBlockPx);
        const int x_end = std::min(size, bx + kHandReuseBlockPx);
        int64_t sum = 0;
        for (int y = by; y < y_end; ++y) {
          const uint8_t* a = state.landmarked_crop.ptr<uint8_t>(y) + 3 * bx;
          const uint8_t* b = reuse_crop.ptr<uint8_t>(y) + 3 * bx;
          for (int i = 0; i < 3 * (x_end - bx); ++i) sum += std::abs(int{a[i]} - int{b[i]});
        }
        const int64_t values = 3 * static_cast<int64_t>(y_end - by) * (x_end - bx);
        still = static_cast<double>(sum) <= max_sum * static_cast<double>(values);
      }
    }
    summary.preprocess_s += Seconds(start);
    return still;
  }

  // The hand's crop from the pose alone: the pose's square, refined by hand_recrop when
  // that is on and its answer lies on the pose's hand.
  template <typename OnPoseHand>
  StatusOr<Roi> RoiFromPose(
      const cv::Mat& image, Point2 wrist, Point2 index, Point2 pinky, OnPoseHand on_pose_hand) {
    Roi roi = HandRoiFromPose(wrist, index, pinky, kHandRoiFallbackScale, 0.0);
    if (options.hand_recrop) {
      const Roi recrop_roi =
          HandRoiFromPose(wrist, index, pinky, kHandRecropRoiScale, kHandRecropRoiShiftY);
      CutCrop(image, recrop_roi, kRecropSlot);
      ARCO_RETURN_IF_ERROR(Run(kRecropSlot));
      const auto decode = Clock::now();
      const Network& net = *networks[kRecropSlot];
      const int size = net.info().input_width;
      const std::vector<float>& raw = net.output("crop").data;
      const Point2 centre = recrop_roi.CropPixelToImage(raw[0], raw[1], size);
      const Point2 edge = recrop_roi.CropPixelToImage(raw[2], raw[3], size);
      const Roi refined =
          RoiFromAlignmentPoints(centre, edge, -kPi / 2, 1.0, kHandRoiFromRecropShiftY);
      // Keep the refinement only when it is plausible: on this hand, and between 1 and
      // 8 wrist-to-middle lengths wide (else the pose-derived crop).
      if (on_pose_hand(refined)) roi = refined;
      summary.postprocess_s += Seconds(decode);
    }
    return roi;
  }

  // The hand landmarker on `roi`: 21 points from `first` when the presence reaches
  // min_hand_presence (left as they are otherwise); returns the presence.
  StatusOr<double> HandInRoi(const cv::Mat& image, const Roi& roi, ScoredPoint* first) {
    CutCrop(image, roi, kHandSlot);
    ARCO_RETURN_IF_ERROR(Run(kHandSlot));
    const auto decode = Clock::now();
    const Network& net = *networks[kHandSlot];
    const double presence = net.output("presence").data[0];
    if (presence >= options.min_hand_presence) {
      const int size = net.info().input_width;
      const std::vector<float>& raw = net.output("landmarks").data;
      for (int i = 0; i < kNumHandLandmarks; ++i) {
        hand_points[i] = roi.CropPixelToImage(raw[3 * i], raw[3 * i + 1], size);
        SetPoint(first + i, hand_points[i], presence);
      }
    }
    summary.postprocess_s += Seconds(decode);
    return presence;
  }
};

StatusOr<WholeBodyTracker> WholeBodyTracker::Create(const WholeBodyOptions& options) {
  ARCO_RETURN_IF_ERROR(options.Validate());
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  const std::string dir = options.models_dir.empty() ? DefaultModelsDir() : options.models_dir;
  NetworkOptions network_options;
  network_options.num_threads = options.num_threads;
  network_options.runtime = options.runtime;
  const std::array<ModelId, 4> ids = {ModelId::kPoseDetection,
                                      PoseLandmarkModel(options.pose_model),
                                      ModelId::kHandRecrop,
                                      HandLandmarkModel(options.hand_model)};
  for (size_t k = 0; k < ids.size(); ++k) {
    impl->summary.models[k].model = ids[k];
    if (k == kRecropSlot && !options.hand_recrop) continue;
    ARCO_ASSIGN_OR_RETURN(Network network, Network::Load(ids[k], dir, network_options));
    impl->networks[k].emplace(std::move(network));
    const Network* net = &*impl->networks[k];
    impl->summary.models[k].runtime = net->runtime_name();
    impl->inputs[k].assign(
        3 * static_cast<size_t>(net->info().input_width) * net->info().input_height, 0.0f);
  }
  return WholeBodyTracker(std::move(impl));
}

WholeBodyTracker::WholeBodyTracker(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
WholeBodyTracker::WholeBodyTracker(WholeBodyTracker&&) noexcept = default;
WholeBodyTracker& WholeBodyTracker::operator=(WholeBodyTracker&&) noexcept = default;
WholeBodyTracker::~WholeBodyTracker() = default;

const WholeBodyOptions& WholeBodyTracker::options() const { return impl_->options; }
const WholeBodySummary& WholeBodyTracker::summary() const { return impl_->summary; }

void WholeBodyTracker::Reset() {
  impl_->tracking = false;
  impl_->pose_roi = Roi();
  impl_->person_seen = false;
  for (Impl::HandState& hand : impl_->hand_state) hand.found = false;
}

StatusOr<double> WholeBodyTracker::LandmarkHand(const media::Image& frame,
                                                const Roi& roi,
                                                ScoredPoint* first) {
  if (frame.format != media::PixelFormat::kRgb8 || frame.width < 2 || frame.height < 2 ||
      frame.pixels.size() != frame.row_bytes() * static_cast<size_t>(frame.height)) {
    throw std::invalid_argument(
        "WholeBodyTracker::LandmarkHand takes an RGB8 image of at least 2 x 2");
  }
  if (!roi.IsFinite() || !(roi.side_px > 0)) {
    throw std::invalid_argument("WholeBodyTracker::LandmarkHand takes a finite, non-empty ROI");
  }
  const cv::Mat image(
      frame.height, frame.width, CV_8UC3, const_cast<uint8_t*>(frame.pixels.data()));
  for (int i = 0; i < kNumHandLandmarks; ++i) first[i] = ScoredPoint();
  return impl_->HandInRoi(image, roi, first);
}

StatusOr<WholeBodyFrame> WholeBodyTracker::Track(const media::Image& frame) {
  if (frame.format != media::PixelFormat::kRgb8 || frame.width < 2 || frame.height < 2 ||
      frame.pixels.size() != frame.row_bytes() * static_cast<size_t>(frame.height)) {
    throw std::invalid_argument("WholeBodyTracker::Track takes an RGB8 image of at least 2 x 2");
  }
  Impl& s = *impl_;
  // A view of the caller's pixels; cv::warpAffine only reads them.
  const cv::Mat image(
      frame.height, frame.width, CV_8UC3, const_cast<uint8_t*>(frame.pixels.data()));
  WholeBodyFrame out;
  s.summary.frames += 1;

  double presence = std::numeric_limits<double>::quiet_NaN();
  bool have_pose = false;
  if (s.tracking) {
    ARCO_ASSIGN_OR_RETURN(presence, s.PoseLandmarks(image, s.pose_roi));
    have_pose = presence >= s.options.min_pose_presence;
  }
  if (!have_pose) {
    s.tracking = false;
    out.detector_ran = true;
    s.summary.detector_runs += 1;
    if (s.person_seen) s.summary.redetections += 1;
    Roi roi;
    ARCO_ASSIGN_OR_RETURN(bool found, s.Detect(image, &roi));
    if (found) {
      ARCO_ASSIGN_OR_RETURN(presence, s.PoseLandmarks(image, roi));
      have_pose = presence >= s.options.min_pose_presence;
    }
  }
  out.pose_presence = static_cast<float>(presence);
  if (!have_pose) {
    for (Impl::HandState& hand : s.hand_state) hand.found = false;
    return out;
  }

  // The body points, and the next frame's ROI from the auxiliary alignment points.
  const auto start = Clock::now();
  out.person = true;
  s.person_seen = true;
  s.summary.frames_with_person += 1;
  const std::array<int, wholebody::kNumBody>& body = MediaPipeOfCocoBody();
  for (int i = 0; i < wholebody::kNumBody; ++i) {
    SetPoint(
        &out.points[wholebody::kBodyFirst + i], s.pose_points[body[i]], s.pose_scores[body[i]]);
  }
  const std::array<int, wholebody::kNumFeet>& feet = MediaPipeOfCocoFeet();
  for (int i = 0; i < wholebody::kNumFeet; ++i) {
    if (feet[i] < 0) continue;
    SetPoint(
        &out.points[wholebody::kFeetFirst + i], s.pose_points[feet[i]], s.pose_scores[feet[i]]);
  }
  s.pose_roi = RoiFromAlignmentPoints(s.pose_points[mediapipe_pose::kAuxHipCentre],
                                      s.pose_points[mediapipe_pose::kAuxBodyCircle],
                                      kPi / 2,
                                      kPoseRoiScale);
  s.tracking = s.pose_roi.IsFinite() && s.pose_roi.side_px >= kMinRoiSidePx;
  s.summary.postprocess_s += Seconds(start);

  // The person's left hand is MediaPipe's left (15, 17, 19) and COCO's left.
  ARCO_ASSIGN_OR_RETURN(const double left,
                        s.Hand(image,
                               0,
                               mediapipe_pose::kLeftWrist,
                               mediapipe_pose::kLeftIndex,
                               mediapipe_pose::kLeftPinky,
                               &out.points[wholebody::kLeftHandFirst]));
  ARCO_ASSIGN_OR_RETURN(const double right,
                        s.Hand(image,
                               1,
                               mediapipe_pose::kRightWrist,
                               mediapipe_pose::kRightIndex,
                               mediapipe_pose::kRightPinky,
                               &out.points[wholebody::kRightHandFirst]));
  out.left_hand_presence = static_cast<float>(left);
  out.right_hand_presence = static_cast<float>(right);
  out.left_hand = left >= s.options.min_hand_presence;
  out.right_hand = right >= s.options.min_hand_presence;
  s.summary.frames_with_left_hand += out.left_hand ? 1 : 0;
  s.summary.frames_with_right_hand += out.right_hand ? 1 : 0;
  return out;
}

}  // namespace arco::detect
