// The multi-view fit on the real 20-camera SPD rig (its calibration, with its
// real distortion) and generated hands with known truth.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "arco/camera/calibration_io.h"
#include "arco/hand/fit.h"
#include "arco/hand/hand_test_util.h"
#include "arco/hand/synthetic_rig.h"
#include "arco/util/file_io.h"

namespace arco::hand {
namespace {

// Session cello_1113_scale: 0.344 Metashape units measure the 695 mm nut-bridge
// distance (../shared/data/spd/README.md), so one unit is about 2020 mm.
constexpr double kMmPerUnit = 695.0 / 0.344;

// The point nearest (least squares) to every camera's optical axis: where the rig
// looks, i.e. where the performer sits.
Eigen::Vector3d RigFocus(const std::vector<Camera>& cameras) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const Camera& c : cameras) {
    const Eigen::Vector3d d = c.cam_from_world.rotation.row(2).transpose();
    const Eigen::Matrix3d p = Eigen::Matrix3d::Identity() - d * d.transpose();
    a += p;
    b += p * c.CenterInWorld();
  }
  return a.ldlt().solve(b);
}

TEST(FitHandMultiView, RecoversGeneratedHandsInTheRealSpdRig) {
  const std::string path = std::string(ARCO_SHARED_DATA_DIR) + "/spd/cello_1113_scale_camera.xml";
  const StatusOr<std::string> text = ReadFileToString(path);
  ASSERT_TRUE(text.ok()) << text.status().message();
  const StatusOr<Calibration> calibration = ParseMetashapeXml(*text, path);
  ASSERT_TRUE(calibration.ok()) << calibration.status().message();
  std::vector<Camera> cameras = calibration->rig.cameras;
  ASSERT_EQ(cameras.size(), 20u);
  for (Camera& c : cameras) c.cam_from_world.translation *= kMmPerUnit;
  const Eigen::Vector3d focus = RigFocus(cameras);

  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::mt19937 rng(128);
  const int trials = 8;
  double mean_mm = 0, worst_mm = 0, mean_trusted = 0;
  for (int trial = 0; trial < trials; ++trial) {
    const HandPose truth = testing::RandomPose(model, rng, 0.05, focus);
    const HandPointsMm points = ForwardKinematics(model, truth);
    std::vector<HandKeypoints2d> views = testing::ProjectHand(cameras, points, 2.0, 0.05, rng);
    int visible_views = 0;
    for (size_t v = 0; v < views.size(); ++v) {  // keypoints outside the image are missing
      bool any = false;
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        const Eigen::Vector2d& px = views[v].pixels[k];
        if (!(px.x() >= 0 && px.y() >= 0 && px.x() < cameras[v].width &&
              px.y() < cameras[v].height)) {
          views[v].scores[k] = 0;
        } else {
          any = true;
        }
      }
      visible_views += any;
    }
    const HandFitResult r =
        FitHandMultiView(model, cameras, views, HandFitInit{}, HandFitOptions{});
    ASSERT_TRUE(r.ok) << r.problem;
    EXPECT_EQ(CountLimitViolations(model, r.pose, 0.0), 0);
    double mm = 0;
    const HandPointsMm fitted = ForwardKinematics(model, r.pose);
    for (int k = 0; k < kNumHandKeypoints; ++k)
      mm += (fitted[k] - points[k]).norm() / kNumHandKeypoints;
    mean_mm += mm / trials;
    worst_mm = std::max(worst_mm, mm);
    int trusted = 0;
    for (uint8_t t : r.trusted_views) trusted += t;
    mean_trusted += double(trusted) / trials;
    EXPECT_GE(visible_views, 10);
  }
  std::printf(
      "[ fit2d ] real SPD rig (20 cameras, real distortion), 2 px noise, 5%% outliers: "
      "MPJPE mean %.2f mm, worst %.2f mm, %.1f views trusted\n",
      mean_mm,
      worst_mm,
      mean_trusted);
  EXPECT_LT(mean_mm, 2.0);
  EXPECT_LT(worst_mm, 4.0);
}

}  // namespace
}  // namespace arco::hand
