// The tracker's pieces without the models: ROI geometry, SSD decoding and weighted NMS,
// the MediaPipe -> COCO-WholeBody mapping, and WholeBodyOptions validation.
#include "arco/detect/roi.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "arco/detect/ssd.h"
#include "arco/detect/wholebody.h"
#include "arco/detect/wholebody_mapping.h"
#include "arco/registry/keypoint_layout.h"

namespace arco::detect {
namespace {

constexpr double kPi = 3.14159265358979323846;

void ExpectNear(Point2 a, Point2 b, double tolerance = 1e-9) {
  EXPECT_NEAR(a.x, b.x, tolerance);
  EXPECT_NEAR(a.y, b.y, tolerance);
}

TEST(Roi, AffineMatchesToImageAtPixelCentres) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    Roi roi;
    roi.centre = {500 + 300 * u(rng), 400 + 300 * u(rng)};
    roi.side_px = 200 + 100 * u(rng);
    roi.rotation_rad = kPi * u(rng);
    double m[6];
    roi.CropPixelToImageAffine(256, m);
    for (int uv : {0, 17, 255}) {
      const Point2 expected = roi.ToImage((uv + 0.5) / 256, (255 - uv + 0.5) / 256);
      const Point2 got = {m[0] * uv + m[1] * (255 - uv) + m[2],
                          m[3] * uv + m[4] * (255 - uv) + m[5]};
      ExpectNear(got, expected);
    }
  }
}

// The square's top edge centre is the scale point (side = 2 |scale_point - centre|,
// turned so centre -> scale_point is "up"): for any direction.
TEST(RoiFromAlignmentPoints, ScalePointIsTopCentreAtAnyAngle) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 50; ++trial) {
    const Point2 centre = {300 * u(rng), 300 * u(rng)};
    const Point2 scale_point = centre + Point2{100 * u(rng), 100 * u(rng)};
    const Roi roi = RoiFromAlignmentPoints(centre, scale_point, kPi / 2, 1.0);
    ExpectNear(roi.centre, centre);
    EXPECT_NEAR(roi.side_px, 2 * Norm(scale_point - centre), 1e-9);
    ExpectNear(roi.ToImage(0.5, 0.0), scale_point, 1e-6);
    EXPECT_GE(roi.rotation_rad, -kPi);
    EXPECT_LT(roi.rotation_rad, kPi);
    // Target -90 degrees (hand_recrop's): the scale point is the bottom edge's centre.
    const Roi down = RoiFromAlignmentPoints(centre, scale_point, -kPi / 2, 1.0);
    ExpectNear(down.ToImage(0.5, 1.0), scale_point, 1e-6);
  }
}

TEST(RoiFromAlignmentPoints, UprightBodyHasNoRotationAndShiftIsBeforeScaling) {
  const Roi upright = RoiFromAlignmentPoints({100, 200}, {100, 100}, kPi / 2, 1.25);
  EXPECT_NEAR(upright.rotation_rad, 0, 1e-12);
  EXPECT_NEAR(upright.side_px, 250, 1e-9);
  // Lying with the head to the right: the crop turns by +90 degrees.
  EXPECT_NEAR(AlignmentRotation({0, 0}, {10, 0}, kPi / 2), kPi / 2, 1e-12);
  // shift_y -0.1 of the unscaled side (200) towards the crop's top, then scale 2.
  const Roi shifted = RoiFromAlignmentPoints({100, 200}, {100, 100}, kPi / 2, 2.0, -0.1);
  ExpectNear(shifted.centre, {100, 180});
  EXPECT_NEAR(shifted.side_px, 400, 1e-9);
}

TEST(WholeImageRoi, LetterboxesTheLongSide) {
  const Roi roi = WholeImageRoi(640, 480);
  EXPECT_EQ(roi.side_px, 640);
  ExpectNear(roi.ToImage(0, 0), {-0.5, 239.5 - 320});
  ExpectNear(roi.ToImage(1, 1), {639.5, 239.5 + 320});
}

TEST(HandRoiFromPose, CentredOnTheMiddleFingerBaseTurnedFingersUp) {
  // A hand pointing left: wrist at x 100, knuckles at x 40.
  const Point2 wrist{100, 50}, index{40, 44}, pinky{40, 62};
  const Roi roi = HandRoiFromPose(wrist, index, pinky, 1.0, 0.0);
  const Point2 middle = {40, (2 * 44 + 62) / 3.0};
  ExpectNear(roi.centre, middle);
  EXPECT_NEAR(roi.side_px, 2 * Norm(middle - wrist), 1e-9);
  // The crop's top is further left, away from the wrist.
  EXPECT_LT(roi.ToImage(0.5, 0).x, middle.x - 50);
}

// MediaPipe's next-frame hand crop from the hand's own points: an upright hand (wrist
// below the finger bases) gives an upright square of twice the points' extent, moved up
// (towards the fingers) by 0.1 of its side; the same hand turned by any angle gives the
// same square turned with it; points left out do not count; without the wrist or a
// finger base there is no crop.
TEST(HandRoiFromLandmarks, TwiceTheBoxShiftedTowardsTheFingersTurnedWithTheHand) {
  std::array<Point2, 21> upright;
  // A hand 40 px wide: the wrist at (0, 60); finger bases at y = 0; joints above them.
  for (int i = 0; i < 21; ++i) upright[i] = {0, 60};
  const double base_x[4] = {-15, -5, 5, 15};  // index, middle, ring, little bases
  for (int f = 0; f < 4; ++f) {
    for (int j = 0; j < 4; ++j) upright[5 + 4 * f + j] = {base_x[f], -15.0 * j};
  }
  for (int j = 1; j < 5; ++j) upright[j] = {-20.0 - 2 * j, 50.0 - 12 * j};  // the thumb
  // The middle of the bases ((index + ring) / 2 + middle) / 2 is (-5, 0): move the wrist
  // under it so the hand points straight up.
  upright[0] = {-5, 60};
  std::optional<Roi> roi = HandRoiFromLandmarks(upright.data());
  ASSERT_TRUE(roi.has_value());
  EXPECT_NEAR(roi->rotation_rad, 0, 1e-12);
  // Box: x from -28 to 15 (43), y from -45 to 60 (105): side 210, centre (-6.5, 7.5)
  // moved up by 21.
  EXPECT_NEAR(roi->side_px, 210, 1e-9);
  EXPECT_NEAR(roi->centre.x, -6.5, 1e-9);
  EXPECT_NEAR(roi->centre.y, 7.5 - 21, 1e-9);
  for (double angle : {0.3, -1.2, 2.5}) {
    const Point2 pivot = {100, 200};
    std::array<Point2, 21> turned;
    // Turning the image points by +angle (x right, y down: clockwise on screen) turns
    // the crop by +angle in MediaPipe's convention.
    const auto turn = [&](Point2 p) {
      const double c = std::cos(angle), s = std::sin(angle);
      return Point2{pivot.x + c * p.x - s * p.y, pivot.y + s * p.x + c * p.y};
    };
    for (int i = 0; i < 21; ++i) turned[i] = turn(upright[i]);
    std::optional<Roi> r = HandRoiFromLandmarks(turned.data());
    ASSERT_TRUE(r.has_value());
    EXPECT_NEAR(r->rotation_rad, angle, 1e-9);
    EXPECT_NEAR(r->side_px, 210, 1e-9);
    const Point2 centre = turn(roi->centre);
    EXPECT_NEAR(r->centre.x, centre.x, 1e-9);
    EXPECT_NEAR(r->centre.y, centre.y, 1e-9);
  }
  // The tracking subset keeps each finger's base and next joint only (and the thumb
  // without its tip): the box is y -15 .. 60, side 2 x 75.
  std::optional<Roi> subset = HandRoiFromLandmarks(upright.data(), kHandTrackingRoiPoints);
  ASSERT_TRUE(subset.has_value());
  EXPECT_NEAR(subset->side_px, 150, 1e-9);
  bool no_wrist[21];
  std::fill(no_wrist, no_wrist + 21, true);
  no_wrist[0] = false;
  EXPECT_FALSE(HandRoiFromLandmarks(upright.data(), no_wrist).has_value());
  std::array<Point2, 21> collapsed;
  collapsed.fill({3, 4});
  EXPECT_FALSE(HandRoiFromLandmarks(collapsed.data()).has_value());
}

TEST(SsdAnchors, PoseDetectionGrid) {
  const std::vector<Point2>& anchors = PoseDetectionAnchors();
  ASSERT_EQ(anchors.size(), 2254u);
  ExpectNear(anchors[0], {0.5 / 28, 0.5 / 28});
  ExpectNear(anchors[1], {0.5 / 28, 0.5 / 28});
  ExpectNear(anchors[2], {1.5 / 28, 0.5 / 28});
  ExpectNear(anchors[28 * 28 * 2], {0.5 / 14, 0.5 / 14});
  ExpectNear(anchors.back(), {6.5 / 7, 6.5 / 7});
  EXPECT_THROW(SsdAnchors(224, {{0, 2}}), std::invalid_argument);
}

TEST(DecodeSsd, BoxesAndKeypointsRelativeToAnchors) {
  const std::vector<Point2> anchors = {{0.25, 0.25}, {0.75, 0.5}, {0.5, 0.5}};
  // 1 keypoint: (cx, cy, w, h, kx, ky) in input pixels of a 100 px input.
  const std::vector<float> boxes = {10,
                                    -5,
                                    20,
                                    40,
                                    1,
                                    2,  //
                                    0,
                                    0,
                                    10,
                                    10,
                                    0,
                                    0,  //
                                    0,
                                    0,
                                    50,
                                    50,
                                    -10,
                                    0};
  const std::vector<float> scores = {0.0f, -3.0f, 1e9f};
  const std::vector<SsdDetection> d = DecodeSsd(boxes.data(), scores.data(), anchors, 1, 100, 0.4);
  ASSERT_EQ(d.size(), 2u);  // sigmoid(-3) = 0.047 is below 0.4
  EXPECT_DOUBLE_EQ(d[0].score, 0.5);
  EXPECT_NEAR(d[0].x_min, 0.35 - 0.1, 1e-9);
  EXPECT_NEAR(d[0].y_min, 0.2 - 0.2, 1e-9);
  EXPECT_NEAR(d[0].width, 0.2, 1e-9);
  EXPECT_NEAR(d[0].height, 0.4, 1e-9);
  ExpectNear(d[0].keypoints[0], {0.26, 0.27});
  EXPECT_DOUBLE_EQ(d[1].score, 1.0);  // the logit is clipped to 100
  ExpectNear(d[1].keypoints[0], {0.4, 0.5});
}

SsdDetection Box(double score, double x, double y, double side, Point2 keypoint) {
  SsdDetection d;
  d.score = score;
  d.x_min = x;
  d.y_min = y;
  d.width = d.height = side;
  d.keypoints = {keypoint};
  return d;
}

TEST(WeightedNonMaxSuppression, AveragesOverlapsByScoreKeepsTheRest) {
  std::vector<SsdDetection> in = {Box(0.6, 0.1, 0.1, 0.2, {0.3, 0.3}),
                                  Box(0.9, 0.6, 0.6, 0.2, {0.7, 0.7}),
                                  Box(0.8, 0.12, 0.1, 0.2, {0.1, 0.1})};
  EXPECT_NEAR(IntersectionOverUnion(in[0], in[2]), 0.18 * 0.2 / (0.08 - 0.18 * 0.2), 1e-12);
  EXPECT_EQ(IntersectionOverUnion(in[0], in[1]), 0.0);
  const std::vector<SsdDetection> out = WeightedNonMaxSuppression(in, 0.3);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].score, 0.9);  // best first, alone
  EXPECT_NEAR(out[0].x_min, 0.6, 1e-12);
  EXPECT_EQ(out[1].score, 0.8);  // the best of the merged pair keeps its score
  EXPECT_NEAR(out[1].x_min, (0.8 * 0.12 + 0.6 * 0.1) / 1.4, 1e-12);
  EXPECT_NEAR(out[1].keypoints[0].x, (0.8 * 0.1 + 0.6 * 0.3) / 1.4, 1e-12);
  // Above the IoU threshold nothing merges.
  EXPECT_EQ(WeightedNonMaxSuppression(in, 0.9).size(), 3u);
}

TEST(WholeBodyMapping, NamesAgreeWithTheLayout) {
  const KeypointLayout* layout = FindKeypointLayout("coco_wholebody_133");
  ASSERT_NE(layout, nullptr);
  const auto& names = mediapipe_pose::Names();
  std::set<int> used;
  for (int i = 0; i < wholebody::kNumBody; ++i) {
    const int mp = MediaPipeOfCocoBody()[i];
    EXPECT_EQ(layout->names[wholebody::kBodyFirst + i], names[mp]);
    EXPECT_TRUE(used.insert(mp).second);
  }
  for (int i = 0; i < wholebody::kNumFeet; ++i) {
    const std::string coco = layout->names[wholebody::kFeetFirst + i];
    const int mp = MediaPipeOfCocoFeet()[i];
    if (coco.find("small_toe") != std::string::npos) {
      EXPECT_EQ(mp, -1) << coco;
      continue;
    }
    ASSERT_GE(mp, 0) << coco;
    EXPECT_TRUE(used.insert(mp).second);
    std::string expected = coco;
    const size_t toe = expected.find("big_toe");
    if (toe != std::string::npos) expected.replace(toe, 7, "foot_index");
    EXPECT_EQ(names[mp], expected) << coco;
  }
  EXPECT_EQ(std::string(names[mediapipe_pose::kLeftWrist]), "left_wrist");
  EXPECT_EQ(std::string(names[mediapipe_pose::kRightIndex]), "right_index");
  EXPECT_EQ(std::string(names[mediapipe_pose::kLeftPinky]), "left_pinky");
  EXPECT_EQ(layout->names[wholebody::kLeftHandFirst], "left_hand_wrist");
}

TEST(WholeBodyOptions, ValidateNamesTheField) {
  EXPECT_TRUE(WholeBodyOptions().Validate().ok());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    const char* field;
    double WholeBodyOptions::*member;
  };
  for (const Case& c :
       {Case{"min_detection_score", &WholeBodyOptions::min_detection_score},
        Case{"nms_min_iou", &WholeBodyOptions::nms_min_iou},
        Case{"min_pose_presence", &WholeBodyOptions::min_pose_presence},
        Case{"min_hand_presence", &WholeBodyOptions::min_hand_presence},
        Case{"min_hand_tracking_presence", &WholeBodyOptions::min_hand_tracking_presence}}) {
    for (double bad : {-0.01, 1.01, nan, std::numeric_limits<double>::infinity()}) {
      WholeBodyOptions options;
      options.*c.member = bad;
      const Status status = options.Validate();
      ASSERT_FALSE(status.ok()) << c.field << " " << bad;
      EXPECT_NE(status.message().find(std::string("WholeBodyOptions.") + c.field),
                std::string::npos)
          << status.message();
    }
    WholeBodyOptions edge;
    edge.*c.member = 1.0;
    EXPECT_TRUE(edge.Validate().ok());
  }
  for (int threads : {0, -1, 1025}) {
    WholeBodyOptions options;
    options.num_threads = threads;
    EXPECT_NE(options.Validate().message().find("WholeBodyOptions.num_threads"), std::string::npos);
  }
  for (double bad : {-0.5, 16.5, nan}) {
    WholeBodyOptions options;
    options.hand_reuse_max_change = bad;
    EXPECT_NE(options.Validate().message().find("WholeBodyOptions.hand_reuse_max_change"),
              std::string::npos)
        << bad;
  }
  for (double edge : {0.0, 16.0}) {
    WholeBodyOptions options;
    options.hand_reuse_max_change = edge;
    EXPECT_TRUE(options.Validate().ok()) << edge;
  }
  for (int levels : {-1, 3}) {
    WholeBodyOptions options;
    options.detection_tile_levels = levels;
    EXPECT_NE(options.Validate().message().find("WholeBodyOptions.detection_tile_levels"),
              std::string::npos);
  }
  WholeBodyOptions bad_model;
  bad_model.pose_model = static_cast<PoseModel>(7);
  EXPECT_FALSE(bad_model.Validate().ok());
  // Create validates before loading anything.
  WholeBodyOptions zero_threads;
  zero_threads.num_threads = 0;
  StatusOr<WholeBodyTracker> tracker = WholeBodyTracker::Create(zero_threads);
  ASSERT_FALSE(tracker.ok());
  EXPECT_NE(tracker.status().message().find("num_threads"), std::string::npos);
}

TEST(PoseModel, ParsesItsNames) {
  for (PoseModel model : {PoseModel::kLite, PoseModel::kFull, PoseModel::kHeavy}) {
    StatusOr<PoseModel> parsed = ParsePoseModel(PoseModelName(model));
    ASSERT_TRUE(parsed.ok());
    EXPECT_EQ(*parsed, model);
  }
  EXPECT_EQ(PoseLandmarkModel(PoseModel::kHeavy), ModelId::kPoseLandmarkHeavy);
  StatusOr<PoseModel> bad = ParsePoseModel("huge");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("lite, full or heavy"), std::string::npos);
}

// A missing model file: one line naming it and pointing to scripts/setup, from Create.
TEST(WholeBodyTracker, MissingModelNamesTheFileAndScriptsSetup) {
  WholeBodyOptions options;
  options.models_dir = "/nonexistent/models";
  StatusOr<WholeBodyTracker> tracker = WholeBodyTracker::Create(options);
  ASSERT_FALSE(tracker.ok());
  EXPECT_EQ(tracker.status().message(),
            "/nonexistent/models/pose_detection.onnx: model file not found; run "
            "scripts/setup to fetch and convert the models (docs/detect.md)");
}

}  // namespace
}  // namespace arco::detect
