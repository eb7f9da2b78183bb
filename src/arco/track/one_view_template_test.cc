// PoseTemplateInOneView on a generated view of known truth: a cello-sized rigid body posed
// in front of one camera with lens distortion, its points labelled with half a pixel of
// noise (a one-phone capture's `arco track --labels`).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "arco/testing/look_at.h"
#include "arco/track/instrument_tracker.h"

namespace arco::track {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct View {
  Camera camera;
  Rigid3d world_from_body;
  std::vector<Eigen::Vector3d> model;  // per name, the body's frame (NaN: not in the model)
  FrameLabels labels;
};

// Names: the body's seven points, then one the model lacks ("bow_hair"), then one the
// labeller left out ("end_pin"). `scale`: the labelled instrument's size over the model's.
View MakeView(double noise_px, double scale = 1.0) {
  View v;
  Camera& c = v.camera;
  c.width = 1920, c.height = 1080, c.fx = c.fy = 1500, c.cx = 960, c.cy = 540;
  c.distortion.k1 = -0.05;
  const Eigen::Vector3d centre(300, -2500, 900);
  c.cam_from_world.rotation = testing::CamFromWorldLookingAt(centre, Eigen::Vector3d(0, 0, 700));
  c.cam_from_world.translation = -c.cam_from_world.rotation * centre;
  // The strings along x, the front +z, tail and scroll off the strings' plane.
  v.model = {{881, 0, -25},
             {695, 12, 0},
             {695, -12, 0},
             {0, 24, 0},
             {0, -24, 0},
             {-377, 0, -75},
             {-500, 0, -110},
             Eigen::Vector3d::Constant(kNaN),
             {-691, 0, -120}};
  v.labels.point_names = {"scroll_top",
                          "nut_l",
                          "nut_r",
                          "bridge_l",
                          "bridge_r",
                          "tail_gut",
                          "tail_block",
                          "bow_hair",
                          "end_pin"};
  // Upright and turned towards the camera's left, a little back.
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(-1.35, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(1.5, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  v.world_from_body = Rigid3d(R, Eigen::Vector3d(0, 0, 700));
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, noise_px);
  v.labels.pixels.assign(1, {});
  for (size_t p = 0; p < v.model.size(); ++p) {
    // The bow's point is labelled (the model lacks it); the end pin is not.
    const Eigen::Vector3d in_body = v.model[p].allFinite() ? v.model[p] : v.model[0];
    const auto pixel = c.Project(v.world_from_body * (scale * in_body));
    const bool labelled = p + 1 != v.model.size() && pixel.has_value();
    v.labels.pixels[0].push_back(
        labelled ? Eigen::Vector2d(*pixel + Eigen::Vector2d(noise(rng), noise(rng)))
                 : Eigen::Vector2d::Constant(kNaN));
  }
  return v;
}

TEST(PoseTemplateInOneView, PlacesTheModelWhereItsLabelsAre) {
  const View v = MakeView(0.5);
  const auto body = PoseTemplateInOneView(v.camera, v.labels, v.model);
  ASSERT_TRUE(body.ok()) << body.status().message();
  ASSERT_EQ(body->points.size(), v.model.size());
  double worst_mm = 0, worst_px = 0;
  for (size_t p = 0; p < 7; ++p) {
    ASSERT_TRUE(body->points[p].allFinite()) << v.labels.point_names[p];
    EXPECT_EQ(body->label_views[p], 1);
    worst_mm = std::max(worst_mm, (body->points[p] - v.world_from_body * v.model[p]).norm());
    worst_px =
        std::max(worst_px, (*v.camera.Project(body->points[p]) - v.labels.pixels[0][p]).norm());
  }
  std::printf(
      "one view, 0.5 px labels: worst point %.1f mm from the truth, %.2f px from its "
      "label, rms %.2f px\n",
      worst_mm,
      worst_px,
      body->rms_reprojection_px);
  // 2.7 m away at 1500 px: half a pixel is 0.9 mm across the ray; depth is what one view
  // measures worst.
  EXPECT_LT(worst_mm, 10);
  EXPECT_LT(worst_px, 2);
  EXPECT_LT(body->rms_reprojection_px, 1);
  // No place for a name the model lacks, nor for a point nobody labelled.
  EXPECT_FALSE(body->points[7].allFinite());
  EXPECT_FALSE(body->points[8].allFinite());
  // The features' plane is the one that fits the points best, as with several views: these
  // spread 120 mm off the strings' plane but only +-24 mm across the strings, so it is the
  // plane along the strings and the front, whose normal is the body's y.
  const Eigen::Vector3d across = v.world_from_body.rotation * Eigen::Vector3d::UnitY();
  EXPECT_GT(std::abs(body->plane_normal.dot(across)), std::cos(10 * M_PI / 180));
}

TEST(PoseTemplateInOneView, TheModelsSizeSetsTheDepth) {
  // A real instrument 10 % larger than the model looks like the model 10 % nearer.
  const View v = MakeView(0, 1.1);
  const auto body = PoseTemplateInOneView(v.camera, v.labels, v.model);
  ASSERT_TRUE(body.ok()) << body.status().message();
  const Eigen::Vector3d eye = v.camera.CenterInWorld();
  const double placed = (body->points[3] - eye).norm();
  const double real = (v.world_from_body * (1.1 * v.model[3]) - eye).norm();
  EXPECT_NEAR(placed / real, 1 / 1.1, 0.01);
}

TEST(PoseTemplateInOneView, TooFewLabelsOrLabelsThatFitNoPose) {
  View v = MakeView(0.5);
  for (size_t p = 3; p < v.model.size(); ++p)
    v.labels.pixels[0][p] = Eigen::Vector2d::Constant(kNaN);
  auto body = PoseTemplateInOneView(v.camera, v.labels, v.model);
  ASSERT_FALSE(body.ok());
  EXPECT_EQ(body.status().message(),
            "3 of the instrument's points labelled in the one view: a pose from one view needs "
            "at least 4");
  // Four labels, one of them 150 px off: no pose agrees with all of them.
  v = MakeView(0.5);
  for (size_t p = 4; p < v.model.size(); ++p)
    v.labels.pixels[0][p] = Eigen::Vector2d::Constant(kNaN);
  v.labels.pixels[0][1].y() += 150;
  body = PoseTemplateInOneView(v.camera, v.labels, v.model);
  ASSERT_FALSE(body.ok());
  EXPECT_NE(
      body.status().message().find("the labels do not fit the instrument's shape in one view"),
      std::string::npos)
      << body.status().message();
  // Every label given, the right side of the nut 40 px off (a slip in labelme): the others
  // agree on a pose, and the error names it.
  v = MakeView(0.5);
  v.labels.pixels[0][2].x() += 40;
  body = PoseTemplateInOneView(v.camera, v.labels, v.model);
  ASSERT_FALSE(body.ok());
  EXPECT_EQ(body.status().message().rfind("label nut_r: the labels do not fit the instrument's "
                                          "shape in one view (it is ",
                                          0),
            0u)
      << body.status().message();
}

}  // namespace
}  // namespace arco::track
