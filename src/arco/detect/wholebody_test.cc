// WholeBodyTracker on real images (the models from scripts/setup): a real SPD cellist,
// opencv-doc's messi5.jpg and vtest.avi. docs/detect.md quotes the printed figures.
#include "arco/detect/wholebody.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "arco/detect/models_for_test.h"
#include "arco/detect/roi.h"
#include "arco/media/video_reader.h"
#include "arco/testing/temp_dir.h"

namespace arco::detect {
namespace {

constexpr char kOpencvData[] = "/usr/share/doc/opencv-doc/examples/data/";

media::Image ReadImage(const std::string& path) {
  StatusOr<media::VideoReader> reader = media::VideoReader::Open(path);
  EXPECT_TRUE(reader.ok()) << reader.status().message();
  if (!reader.ok()) return {};
  StatusOr<media::Image> image = reader->ReadFrame(0);
  EXPECT_TRUE(image.ok()) << image.status().message();
  return image.ok() ? *image : media::Image();
}

WholeBodyOptions TestOptions(int threads = 2) {
  WholeBodyOptions options;
  options.num_threads = threads;
  return options;
}

// With ARCO_DETECT_DEBUG_DIR set, writes the frame with its keypoints (body red, left
// hand green, right hand blue) for a look by eye.
void MaybeWriteOverlay(const media::Image& image,
                       const WholeBodyFrame& out,
                       const std::string& name) {
  const char* dir = std::getenv("ARCO_DETECT_DEBUG_DIR");
  if (dir == nullptr) return;
  cv::Mat rgb(image.height, image.width, CV_8UC3, const_cast<uint8_t*>(image.pixels.data()));
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  const int radius = std::max(2, image.width / 400);
  for (int p = 0; p < wholebody::kNumPoints; ++p) {
    const ScoredPoint& k = out.points[p];
    if (std::isnan(k.x_px)) continue;
    const cv::Scalar colour = p >= wholebody::kRightHandFirst  ? cv::Scalar(255, 0, 0)
                              : p >= wholebody::kLeftHandFirst ? cv::Scalar(0, 255, 0)
                                                               : cv::Scalar(0, 0, 255);
    cv::circle(bgr, cv::Point(std::lround(k.x_px), std::lround(k.y_px)), radius, colour, -1);
  }
  cv::imwrite(std::string(dir) + "/" + name + ".png", bgr);
}

// Every point NaN in x, y and score together, or finite with a score in [0, 1].
void ExpectWellFormed(const WholeBodyFrame& out) {
  for (int p = 0; p < wholebody::kNumPoints; ++p) {
    const ScoredPoint& k = out.points[p];
    if (std::isnan(k.score)) {
      EXPECT_TRUE(std::isnan(k.x_px) && std::isnan(k.y_px)) << p;
    } else {
      EXPECT_TRUE(std::isfinite(k.x_px) && std::isfinite(k.y_px)) << p;
      EXPECT_GE(k.score, 0.0f) << p;
      EXPECT_LE(k.score, 1.0f) << p;
    }
  }
  // MediaPipe gives no face points and no small toes.
  for (int p = wholebody::kFaceFirst; p < wholebody::kFaceFirst + wholebody::kNumFace; ++p) {
    EXPECT_TRUE(std::isnan(out.points[p].x_px)) << p;
  }
  EXPECT_TRUE(std::isnan(out.points[wholebody::kFeetFirst + 1].x_px));
  EXPECT_TRUE(std::isnan(out.points[wholebody::kFeetFirst + 4].x_px));
}

bool SameBits(const WholeBodyFrame& a, const WholeBodyFrame& b) {
  return std::memcmp(a.points.data(), b.points.data(), sizeof(a.points)) == 0 &&
         a.person == b.person && a.left_hand == b.left_hand && a.right_hand == b.right_hand;
}

// How far the points scoring >= 0.5 in both frames moved between them: the largest
// and the median move.
struct Moves {
  double largest = 0, median = 0;
};
Moves PointMoves(const WholeBodyFrame& a, const WholeBodyFrame& b) {
  std::vector<double> moves;
  for (int p = 0; p < wholebody::kNumPoints; ++p) {
    const ScoredPoint& pa = a.points[p];
    const ScoredPoint& pb = b.points[p];
    if (std::isnan(pa.score) || std::isnan(pb.score) || pa.score < 0.5 || pb.score < 0.5) continue;
    moves.push_back(std::hypot(pa.x_px - pb.x_px, pa.y_px - pb.y_px));
  }
  Moves result;
  if (moves.empty()) return result;
  std::sort(moves.begin(), moves.end());
  result.largest = moves.back();
  result.median = moves[moves.size() / 2];
  return result;
}

// The real SPD cellist: the player is found, the left hand on the fingerboard, its four
// fingertips between the nut and the neck's lower end near the string line, and the
// right (bow) hand near the frog. A second Track of the same picture tracks (no
// detector) and agrees with the first to a few pixels.
TEST(WholeBodyTracker, CellistLeftHandOnTheFingerboard) {
  ARCO_REQUIRE_MODELS();
  const media::Image image = ReadImage(ARCO_SHARED_DATA_DIR "/spd/example.jpg");
  ASSERT_FALSE(image.empty());
  // Every frame's hands from the pose and hand_recrop (Holistic's way; the hands tracked
  // from their own landmarks, the default: HandsTrackedFromTheirLandmarks... below).
  WholeBodyOptions options = TestOptions();
  options.hand_tracking = false;
  StatusOr<WholeBodyTracker> tracker = WholeBodyTracker::Create(options);
  ASSERT_TRUE(tracker.ok()) << tracker.status().message();
  StatusOr<WholeBodyFrame> out = tracker->Track(image);
  ASSERT_TRUE(out.ok()) << out.status().message();
  MaybeWriteOverlay(image, *out, "cellist");
  ExpectWellFormed(*out);
  std::printf("cellist: pose presence %.3f, left hand %.3f, right hand %.3f\n",
              out->pose_presence,
              out->left_hand_presence,
              out->right_hand_presence);
  EXPECT_TRUE(out->detector_ran);
  ASSERT_TRUE(out->person);
  ASSERT_TRUE(out->left_hand);

  // The fingerboard from example.json: nut and neck's lower end (centres of the
  // labelled left/right points); 40 px is about its width (37 px at the nut, 62 px at
  // the neck's end).
  const double nut_x = (1205.3 + 1242.0) / 2, nut_y = (734.8 + 731.3) / 2;
  const double end_x = (1140.2 + 1201.8) / 2, end_y = (1102.3 + 1104.6) / 2;
  const double neck_length = std::hypot(end_x - nut_x, end_y - nut_y);
  const double ax = (end_x - nut_x) / neck_length, ay = (end_y - nut_y) / neck_length;
  for (int tip : {8, 12, 16, 20}) {
    const ScoredPoint& p = out->points[wholebody::kLeftHandFirst + tip];
    const double dx = p.x_px - nut_x, dy = p.y_px - nut_y;
    const double t = dx * ax + dy * ay;
    const double off_line = std::abs(dx * ay - dy * ax);
    std::printf("left fingertip %d: (%.0f, %.0f) px, %.2f nut -> neck end, %.0f px off the line\n",
                tip,
                p.x_px,
                p.y_px,
                t / neck_length,
                off_line);
    EXPECT_GT(t, 0.0) << tip;
    EXPECT_LT(t, neck_length) << tip;
    EXPECT_LT(off_line, 40.0) << tip;
  }
  // The body's left wrist (COCO 9) and the hand's wrist agree.
  const ScoredPoint& body_wrist = out->points[wholebody::kBodyFirst + 9];
  const ScoredPoint& hand_wrist = out->points[wholebody::kLeftHandFirst];
  std::printf("left wrist: body (%.0f, %.0f), hand (%.0f, %.0f) px\n",
              body_wrist.x_px,
              body_wrist.y_px,
              hand_wrist.x_px,
              hand_wrist.y_px);
  EXPECT_LT(std::hypot(body_wrist.x_px - hand_wrist.x_px, body_wrist.y_px - hand_wrist.y_px), 80.0);

  // The bow hand (the person's right) holds the frog (labelled at (968.8, 1533.2)).
  ASSERT_TRUE(out->right_hand);
  double cx = 0, cy = 0;
  for (int i = 0; i < wholebody::kNumHandPoints; ++i) {
    cx += out->points[wholebody::kRightHandFirst + i].x_px / wholebody::kNumHandPoints;
    cy += out->points[wholebody::kRightHandFirst + i].y_px / wholebody::kNumHandPoints;
  }
  std::printf("right hand centre (%.0f, %.0f) px, %.0f px from the frog\n",
              cx,
              cy,
              std::hypot(cx - 968.8, cy - 1533.2));
  EXPECT_LT(std::hypot(cx - 968.8, cy - 1533.2), 150.0);

  // Tracking: the same picture twice more runs no detector. The ROI then comes from the
  // landmarks instead of the detector, and each frame's ROI from the last frame's
  // landmarks: it moves by a few pixels, and the points the model is unsure of (the
  // elbow and knees half hidden by the cello, the heels) follow by up to 2 % of the
  // image height (raw output: no temporal smoothing here), the rest by a few pixels.
  StatusOr<WholeBodyFrame> second = tracker->Track(image);
  StatusOr<WholeBodyFrame> third = tracker->Track(image);
  ASSERT_TRUE(second.ok() && third.ok());
  EXPECT_FALSE(second->detector_ran);
  EXPECT_FALSE(third->detector_ran);
  EXPECT_TRUE(second->person && third->person && third->left_hand && third->right_hand);
  for (const Moves& moves : {PointMoves(*out, *second), PointMoves(*second, *third)}) {
    std::printf(
        "cellist tracked: points scoring >= 0.5 moved by %.1f px (median), %.1f px "
        "(largest)\n",
        moves.median,
        moves.largest);
    EXPECT_LT(moves.largest, 0.025 * image.height);  // 66 px
    EXPECT_LT(moves.median, 6.0);
  }
  const WholeBodySummary& summary = tracker->summary();
  EXPECT_EQ(summary.frames, 3);
  EXPECT_EQ(summary.frames_with_person, 3);
  EXPECT_EQ(summary.detector_runs, 1);
  EXPECT_EQ(summary.redetections, 0);
  EXPECT_EQ(summary.models[0].runs, 1);
  EXPECT_EQ(summary.models[1].runs, 3);
  EXPECT_EQ(summary.models[2].runs, 6);
  EXPECT_EQ(summary.models[3].runs, 6);
  EXPECT_GT(summary.inference_s, 0.0);
  EXPECT_GT(summary.preprocess_s, 0.0);
}

// The median distance between two frames' points of one hand (21 points from `first`).
double HandMedianMove(const WholeBodyFrame& a, const WholeBodyFrame& b, int first) {
  std::vector<double> moves;
  for (int i = 0; i < wholebody::kNumHandPoints; ++i) {
    const ScoredPoint& pa = a.points[first + i];
    const ScoredPoint& pb = b.points[first + i];
    moves.push_back(std::hypot(pa.x_px - pb.x_px, pa.y_px - pb.y_px));
  }
  std::sort(moves.begin(), moves.end());
  return moves[moves.size() / 2];
}

// Hand tracking (MediaPipe's hand tracking graph, issue 28): the cellist three times
// with hand_tracking on runs hand_recrop on the first frame only; the next frames' hands
// take their crops from their own landmarks and stay within a few pixels of the first
// frame's. With hand_reuse_max_change on as well, the same picture once more re-uses
// both hands bit for bit without the landmarker, and the picture moved by 12 px runs it
// again.
TEST(WholeBodyTracker, HandsTrackedFromTheirLandmarksAndStillHandsReused) {
  ARCO_REQUIRE_MODELS();
  const media::Image image = ReadImage(ARCO_SHARED_DATA_DIR "/spd/example.jpg");
  ASSERT_FALSE(image.empty());
  WholeBodyOptions options = TestOptions();
  options.hand_tracking = true;
  options.hand_reuse_max_change = 0;
  StatusOr<WholeBodyTracker> tracker = WholeBodyTracker::Create(options);
  ASSERT_TRUE(tracker.ok()) << tracker.status().message();
  std::vector<WholeBodyFrame> frames;
  for (int k = 0; k < 3; ++k) {
    StatusOr<WholeBodyFrame> out = tracker->Track(image);
    ASSERT_TRUE(out.ok()) << out.status().message();
    ASSERT_TRUE(out->left_hand && out->right_hand) << k;
    EXPECT_GT(out->left_hand_presence, 0.9) << k;
    EXPECT_GT(out->right_hand_presence, 0.9) << k;
    frames.push_back(*out);
  }
  for (int k = 1; k < 3; ++k) {
    const double left = HandMedianMove(frames[0], frames[k], wholebody::kLeftHandFirst);
    const double right = HandMedianMove(frames[0], frames[k], wholebody::kRightHandFirst);
    std::printf(
        "hands tracked from their landmarks, frame %d: left %.1f px, right %.1f px "
        "(median) from frame 0's\n",
        k,
        left,
        right);
    EXPECT_LT(left, 6.0);
    EXPECT_LT(right, 6.0);
  }
  const WholeBodySummary& summary = tracker->summary();
  EXPECT_EQ(summary.models[2].runs, 2);  // hand_recrop: the first frame only
  EXPECT_EQ(summary.models[3].runs, 6);
  EXPECT_EQ(summary.hands_tracked, 4);
  EXPECT_EQ(summary.hands_reused, 0);

  // Still hands re-used: the same picture again runs no hand landmarker.
  options.hand_reuse_max_change = 2;
  tracker = WholeBodyTracker::Create(options);
  ASSERT_TRUE(tracker.ok()) << tracker.status().message();
  StatusOr<WholeBodyFrame> first = tracker->Track(image);
  StatusOr<WholeBodyFrame> again = tracker->Track(image);
  ASSERT_TRUE(first.ok() && again.ok());
  ASSERT_TRUE(again->left_hand && again->right_hand);
  EXPECT_EQ(tracker->summary().hands_reused, 2);
  EXPECT_EQ(tracker->summary().models[3].runs, 2);
  EXPECT_EQ(std::memcmp(&first->points[wholebody::kLeftHandFirst],
                        &again->points[wholebody::kLeftHandFirst],
                        2 * wholebody::kNumHandPoints * sizeof(ScoredPoint)),
            0);
  EXPECT_EQ(again->left_hand_presence, first->left_hand_presence);
  // The picture moved 12 px right and down: the pixels under the last crops changed.
  media::Image moved = media::MakeImage(image.width, image.height, media::PixelFormat::kRgb8);
  const cv::Mat from(image.height, image.width, CV_8UC3, const_cast<uint8_t*>(image.pixels.data()));
  cv::Mat to(moved.height, moved.width, CV_8UC3, moved.pixels.data());
  from(cv::Rect(0, 0, image.width - 12, image.height - 12))
      .copyTo(to(cv::Rect(12, 12, image.width - 12, image.height - 12)));
  StatusOr<WholeBodyFrame> after = tracker->Track(moved);
  ASSERT_TRUE(after.ok());
  ASSERT_TRUE(after->left_hand && after->right_hand);
  EXPECT_EQ(tracker->summary().hands_reused, 2);
  EXPECT_EQ(tracker->summary().models[3].runs, 4);
  // The hands follow the picture.
  const double left = HandMedianMove(*first, *after, wholebody::kLeftHandFirst);
  EXPECT_GT(left, 8.0);
  EXPECT_LT(left, 30.0);

  // The same three frames on 1 thread: the same bits.
  options.num_threads = 1;
  StatusOr<WholeBodyTracker> one = WholeBodyTracker::Create(options);
  ASSERT_TRUE(one.ok()) << one.status().message();
  const std::vector<std::pair<const media::Image*, const WholeBodyFrame*>> runs = {
      {&image, &*first}, {&image, &*again}, {&moved, &*after}};
  for (const auto& [frame, expected] : runs) {
    StatusOr<WholeBodyFrame> out = one->Track(*frame);
    ASSERT_TRUE(out.ok());
    EXPECT_TRUE(SameBits(*out, *expected));
  }
  EXPECT_EQ(one->summary().hands_reused, 2);
}

// Any one missing model stops Create with the line naming that file and scripts/setup
// (here the hand model, the last one loaded).
// The hand landmarker alone on a crop the caller chooses (capture/hand_consistency.h's
// re-run): a crop around the tracked left hand finds it again where Track did; a crop of
// the floor finds nothing; the tracking state is untouched (the next Track tracks).
TEST(WholeBodyTracker, LandmarkHandOnACallersCrop) {
  ARCO_REQUIRE_MODELS();
  const media::Image image = ReadImage(ARCO_SHARED_DATA_DIR "/spd/example.jpg");
  ASSERT_FALSE(image.empty());
  StatusOr<WholeBodyTracker> tracker = WholeBodyTracker::Create(TestOptions());
  ASSERT_TRUE(tracker.ok()) << tracker.status().message();
  StatusOr<WholeBodyFrame> out = tracker->Track(image);
  ASSERT_TRUE(out.ok()) << out.status().message();
  ASSERT_TRUE(out->left_hand);
  const ScoredPoint* hand = &out->points[wholebody::kLeftHandFirst];
  double lo_x = 1e9, lo_y = 1e9, hi_x = -1e9, hi_y = -1e9;
  for (int i = 0; i < 21; ++i) {
    lo_x = std::min<double>(lo_x, hand[i].x_px);
    hi_x = std::max<double>(hi_x, hand[i].x_px);
    lo_y = std::min<double>(lo_y, hand[i].y_px);
    hi_y = std::max<double>(hi_y, hand[i].y_px);
  }
  Roi roi;
  roi.centre = {0.5 * (lo_x + hi_x), 0.5 * (lo_y + hi_y)};
  roi.side_px = 2 * std::max(hi_x - lo_x, hi_y - lo_y);
  roi.rotation_rad = AlignmentRotation(
      {hand[0].x_px, hand[0].y_px}, {hand[9].x_px, hand[9].y_px}, 3.14159265358979 / 2);
  std::array<ScoredPoint, 21> again;
  StatusOr<double> presence = tracker->LandmarkHand(image, roi, again.data());
  ASSERT_TRUE(presence.ok()) << presence.status().message();
  EXPECT_GT(*presence, 0.9);
  std::vector<double> moves;
  for (int i = 0; i < 21; ++i) {
    EXPECT_FLOAT_EQ(again[i].score, static_cast<float>(*presence));
    moves.push_back(std::hypot(again[i].x_px - hand[i].x_px, again[i].y_px - hand[i].y_px));
  }
  std::sort(moves.begin(), moves.end());
  std::printf(
      "LandmarkHand: presence %.3f, median %.1f px from Track's hand\n", *presence, moves[10]);
  EXPECT_LT(moves[10], 0.1 * roi.side_px);
  // The carpet far from the player (network_test.cc's crop): no hand, every point NaN.
  Roi floor;
  floor.centre = {300, 2400};
  floor.side_px = roi.side_px;
  presence = tracker->LandmarkHand(image, floor, again.data());
  ASSERT_TRUE(presence.ok());
  EXPECT_LT(*presence, 0.5);
  for (const ScoredPoint& p : again) EXPECT_TRUE(std::isnan(p.x_px));
  Roi bad;
  bad.side_px = NAN;
  EXPECT_THROW((void)tracker->LandmarkHand(image, bad, again.data()), std::invalid_argument);
  // The tracking state is the one Track left: no detector on the next frame.
  out = tracker->Track(image);
  ASSERT_TRUE(out.ok());
  EXPECT_FALSE(out->detector_ran);
}

TEST(WholeBodyTracker, MissingHandModelNamesIt) {
  ARCO_REQUIRE_MODELS();
  const arco::testing::TempDir temp;
  const std::string& dir = temp.path();
  for (ModelId id : {ModelId::kPoseDetection, ModelId::kPoseLandmarkFull, ModelId::kHandRecrop}) {
    std::filesystem::create_symlink(ModelPath(id), ModelPath(id, dir));
  }
  WholeBodyOptions options = TestOptions(1);
  options.models_dir = dir;
  StatusOr<WholeBodyTracker> tracker = WholeBodyTracker::Create(options);
  ASSERT_FALSE(tracker.ok());
  EXPECT_EQ(tracker.status().message(),
            dir +
                "/hand_landmark_full.onnx: model file not found; run scripts/setup to fetch "
                "and convert the models (docs/detect.md)");
}

TEST(WholeBodyTracker, RejectsAGrayFrame) {
  ARCO_REQUIRE_MODELS();
  StatusOr<WholeBodyTracker> tracker = WholeBodyTracker::Create(TestOptions(1));
  ASSERT_TRUE(tracker.ok()) << tracker.status().message();
  EXPECT_THROW((void)tracker->Track(media::MakeImage(64, 64, media::PixelFormat::kGray8)),
               std::invalid_argument);
  // A black frame holds nobody: every point NaN, the detector ran.
  StatusOr<WholeBodyFrame> out =
      tracker->Track(media::MakeImage(320, 240, media::PixelFormat::kRgb8));
  ASSERT_TRUE(out.ok());
  EXPECT_FALSE(out->person);
  EXPECT_TRUE(out->detector_ran);
  for (const ScoredPoint& p : out->points) EXPECT_TRUE(std::isnan(p.x_px));
}

// opencv-doc's messi5.jpg (548 x 342): the player is found, every point scoring >= 0.5
// lies inside his box (judged by eye: x 55..470, y 50..342, the bottom edge), the points
// spread over most of it, and the hands are on the right sides: he faces the camera,
// so his right hand is on the image's left.
TEST(WholeBodyTracker, MessiInsideHisBox) {
  ARCO_REQUIRE_MODELS();
  const media::Image image = ReadImage(std::string(kOpencvData) + "messi5.jpg");
  if (image.empty()) GTEST_SKIP() << "opencv-doc's messi5.jpg is not installed (scripts/setup)";
  StatusOr<WholeBodyTracker> tracker = WholeBodyTracker::Create(TestOptions());
  ASSERT_TRUE(tracker.ok()) << tracker.status().message();
  StatusOr<WholeBodyFrame> out = tracker->Track(image);
  ASSERT_TRUE(out.ok());
  MaybeWriteOverlay(image, *out, "messi");
  ExpectWellFormed(*out);
  ASSERT_TRUE(out->person);
  ASSERT_TRUE(out->left_hand);
  ASSERT_TRUE(out->right_hand);
  double x_min = 1e9, x_max = -1e9, y_min = 1e9, y_max = -1e9;
  int confident = 0;
  for (int p = 0; p < wholebody::kNumPoints; ++p) {
    const ScoredPoint& k = out->points[p];
    if (std::isnan(k.score) || k.score < 0.5) continue;
    ++confident;
    EXPECT_GE(k.x_px, 55) << p;
    EXPECT_LE(k.x_px, 470) << p;
    EXPECT_GE(k.y_px, 50) << p;
    EXPECT_LE(k.y_px, 342) << p;
    x_min = std::min<double>(x_min, k.x_px);
    x_max = std::max<double>(x_max, k.x_px);
    y_min = std::min<double>(y_min, k.y_px);
    y_max = std::max<double>(y_max, k.y_px);
  }
  std::printf("messi: %d points scoring >= 0.5, spanning x %.0f..%.0f, y %.0f..%.0f px\n",
              confident,
              x_min,
              x_max,
              y_min,
              y_max);
  EXPECT_GE(confident, 17 + 2 * wholebody::kNumHandPoints);
  EXPECT_GT(x_max - x_min, 0.7 * (470 - 55));
  EXPECT_GT(y_max - y_min, 0.7 * (342 - 50));
  EXPECT_LT(out->points[wholebody::kRightHandFirst].x_px, 150);
  EXPECT_GT(out->points[wholebody::kLeftHandFirst].x_px, 300);
}

// opencv-doc's vtest.avi, read with media::VideoReader: its first `frames` frames
// (768 x 576), or with `window` a 240 x 240 window of them around a walker.
std::vector<media::Image> VtestFrames(int frames, bool window) {
  std::vector<media::Image> out;
  StatusOr<media::VideoReader> reader =
      media::VideoReader::Open(std::string(kOpencvData) + "vtest.avi");
  if (!reader.ok()) return out;
  constexpr int kX = 528, kY = 160, kSide = 240;
  media::Image frame;
  for (int f = 0; f < frames; ++f) {
    StatusOr<bool> more = reader->Read(&frame);
    if (!more.ok() || !*more) break;
    if (!window) {
      out.push_back(frame);
      continue;
    }
    media::Image crop = media::MakeImage(kSide, kSide, media::PixelFormat::kRgb8);
    for (int y = 0; y < kSide; ++y) {
      std::memcpy(crop.row(y), frame.row(kY + y) + 3 * kX, crop.row_bytes());
    }
    out.push_back(std::move(crop));
  }
  return out;
}

Point2 Mid(const WholeBodyFrame& out, int a, int b) {
  return {(out.points[a].x_px + out.points[b].x_px) / 2.0,
          (out.points[a].y_px + out.points[b].y_px) / 2.0};
}

// A walker is found and tracked on the whole frames: a person in every frame, the
// detector only on the first frame and when the track is lost (then counted as a
// re-detection), and between tracked frames the torso moves smoothly. The walkers are
// about 90 px tall in 768 x 576 frames: too small for the detector on the whole frame
// (it sees 224 x 224), so this also tests the tile search (detection_tile_levels 1),
// and that without it (0) nobody is found.
TEST(WholeBodyTracker, VtestWalkerTrackedAcrossFrames) {
  ARCO_REQUIRE_MODELS();
  const std::vector<media::Image> frames = VtestFrames(30, /*window=*/false);
  if (frames.empty()) GTEST_SKIP() << "opencv-doc's vtest.avi is not installed (scripts/setup)";
  ASSERT_EQ(frames.size(), 30u);
  WholeBodyOptions whole_frame_only = TestOptions();
  whole_frame_only.detection_tile_levels = 0;
  StatusOr<WholeBodyTracker> untiled = WholeBodyTracker::Create(whole_frame_only);
  ASSERT_TRUE(untiled.ok()) << untiled.status().message();
  StatusOr<WholeBodyFrame> missed = untiled->Track(frames[0]);
  ASSERT_TRUE(missed.ok());
  EXPECT_FALSE(missed->person);

  StatusOr<WholeBodyTracker> tracker = WholeBodyTracker::Create(TestOptions());
  ASSERT_TRUE(tracker.ok()) << tracker.status().message();
  std::vector<WholeBodyFrame> outs;
  int hands_below_threshold = 0;
  for (const media::Image& frame : frames) {
    StatusOr<WholeBodyFrame> out = tracker->Track(frame);
    ASSERT_TRUE(out.ok());
    ExpectWellFormed(*out);
    // A hand below min_hand_presence (0.5; these hands are a few pixels wide) is NaN.
    for (const auto& [found, presence, first] :
         {std::tuple{out->left_hand, out->left_hand_presence, wholebody::kLeftHandFirst},
          std::tuple{out->right_hand, out->right_hand_presence, wholebody::kRightHandFirst}}) {
      EXPECT_EQ(found, presence >= 0.5f);
      if (found) continue;
      hands_below_threshold += presence < 0.5f ? 1 : 0;
      for (int i = 0; i < wholebody::kNumHandPoints; ++i) {
        EXPECT_TRUE(std::isnan(out->points[first + i].x_px));
      }
    }
    outs.push_back(*out);
  }
  EXPECT_GT(hands_below_threshold, 10);
  MaybeWriteOverlay(frames[0], outs[0], "vtest_0");
  MaybeWriteOverlay(frames[29], outs[29], "vtest_29");
  const WholeBodySummary& summary = tracker->summary();
  std::printf("vtest: %lld of %lld frames with a person, %lld detector runs, %lld re-detections\n",
              static_cast<long long>(summary.frames_with_person),
              static_cast<long long>(summary.frames),
              static_cast<long long>(summary.detector_runs),
              static_cast<long long>(summary.redetections));
  EXPECT_TRUE(outs[0].person);
  EXPECT_GE(summary.frames_with_person, 28);
  EXPECT_LE(summary.detector_runs, 4);
  int64_t redetections = 0;
  bool seen = false;
  for (const WholeBodyFrame& out : outs) {
    redetections += out.detector_ran && seen ? 1 : 0;
    seen = seen || out.person;
  }
  EXPECT_EQ(summary.redetections, redetections);
  EXPECT_LE(summary.redetections, 2);

  // Frame to frame, the torso's centre (mid-shoulders + mid-hips) / 2 moves by less
  // than 0.75 torso lengths (mid-shoulders to mid-hips, 26-38 px here). Measured: the
  // walkers' steps are about 8 px (0.3 torso lengths), and 14-18 px (up to 0.65) every
  // third or fourth frame, where vtest's capture timing is uneven; the other walkers
  // are 3+ torso lengths away, so a jump to one of them while tracking fails.
  double largest_step = 0;
  int tracked_pairs = 0;
  for (size_t f = 1; f < outs.size(); ++f) {
    if (!outs[f - 1].person || !outs[f].person || outs[f].detector_ran) continue;
    const Point2 shoulders0 = Mid(outs[f - 1], 5, 6), hips0 = Mid(outs[f - 1], 11, 12);
    const Point2 shoulders1 = Mid(outs[f], 5, 6), hips1 = Mid(outs[f], 11, 12);
    const double torso = Norm(shoulders0 - hips0);
    const double step = Norm(0.5 * (shoulders1 + hips1) - 0.5 * (shoulders0 + hips0)) / torso;
    largest_step = std::max(largest_step, step);
    ++tracked_pairs;
    EXPECT_LT(step, 0.75) << "frame " << f;
    // The torso keeps its length (no collapse, no swap to a far larger person).
    EXPECT_NEAR(Norm(shoulders1 - hips1) / torso, 1.0, 0.3) << "frame " << f;
  }
  std::printf("vtest: %d tracked frame pairs, largest torso-centre step %.2f torso lengths\n",
              tracked_pairs,
              largest_step);
  EXPECT_GE(tracked_pairs, 25);
}

// The same frames give the same output bit for bit with 1 and 2 threads; and Reset()
// makes a tracker continue exactly as a fresh one would (chunks of a video can run in
// parallel, each starting with detection).
TEST(WholeBodyTracker, DeterministicAcrossThreadsAndChunks) {
  ARCO_REQUIRE_MODELS();
  std::vector<media::Image> frames = VtestFrames(8, /*window=*/true);
  if (frames.empty()) GTEST_SKIP() << "opencv-doc's vtest.avi is not installed (scripts/setup)";
  frames.push_back(ReadImage(ARCO_SHARED_DATA_DIR "/spd/example.jpg"));
  std::vector<std::vector<WholeBodyFrame>> runs;
  for (int threads : {1, 2}) {
    StatusOr<WholeBodyTracker> tracker = WholeBodyTracker::Create(TestOptions(threads));
    ASSERT_TRUE(tracker.ok()) << tracker.status().message();
    runs.emplace_back();
    for (const media::Image& frame : frames) {
      StatusOr<WholeBodyFrame> out = tracker->Track(frame);
      ASSERT_TRUE(out.ok());
      runs.back().push_back(*out);
    }
  }
  int with_hands = 0;
  for (size_t f = 0; f < frames.size(); ++f) {
    EXPECT_TRUE(SameBits(runs[0][f], runs[1][f])) << "frame " << f;
    with_hands += runs[0][f].left_hand || runs[0][f].right_hand ? 1 : 0;
  }
  EXPECT_GE(with_hands, 2);  // the hand path ran, too

  // Chunks [0, 4) and [4, 9): one tracker with Reset() between them, and a fresh
  // tracker on the second chunk, agree bit for bit with each other.
  StatusOr<WholeBodyTracker> chunked = WholeBodyTracker::Create(TestOptions(2));
  StatusOr<WholeBodyTracker> fresh = WholeBodyTracker::Create(TestOptions(1));
  ASSERT_TRUE(chunked.ok() && fresh.ok());
  for (size_t f = 0; f < 4; ++f) ASSERT_TRUE(chunked->Track(frames[f]).ok());
  chunked->Reset();
  for (size_t f = 4; f < frames.size(); ++f) {
    StatusOr<WholeBodyFrame> a = chunked->Track(frames[f]);
    StatusOr<WholeBodyFrame> b = fresh->Track(frames[f]);
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_TRUE(SameBits(*a, *b)) << "frame " << f;
    if (f == 4) {
      EXPECT_TRUE(a->detector_ran);
    }
  }
  EXPECT_EQ(chunked->summary().frames, static_cast<int64_t>(frames.size()));
}

}  // namespace
}  // namespace arco::detect
