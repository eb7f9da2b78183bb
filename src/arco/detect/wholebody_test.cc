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
#include <vector>

#include "arco/detect/models_for_test.h"
#include "arco/media/video_reader.h"

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

[[maybe_unused]] bool SameBits(const WholeBodyFrame& a, const WholeBodyFrame& b) {
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
  StatusOr<WholeBodyTracker> tracker = WholeBodyTracker::Create(TestOptions());
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

}  // namespace
}  // namespace arco::detect
