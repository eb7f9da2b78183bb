#include "arco/calibration/bundle_adjustment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "arco/geometry/rotation.h"
#include "arco/testing/synthetic_views.h"

namespace arco::calibration {
namespace {

// A ring of 6 cameras (units m) seeing 10 free points and a rigid body of 5 template points
// (the first four: two pairs whose midpoints are 0.6 m apart) over 8 frames, exactly.
struct Scene {
  Rig truth;
  RigidBody body;  // the truth
  std::vector<BundleTrack> tracks;
};

Scene MakeScene() {
  Scene scene;
  testing::SyntheticRigOptions rig_options;
  rig_options.num_cameras = 6;
  scene.truth = testing::MakeSyntheticRig(rig_options);
  const int frames = 8;
  scene.body.points = {
      {-0.05, 0.3, 0}, {0.05, 0.3, 0}, {-0.05, -0.3, 0}, {0.05, -0.3, 0}, {0, 0, 0.1}};
  const NpyArray<double> free = testing::MakeSyntheticPoints(frames, 10, 7);
  auto observe = [&](BundleTrack track, const Eigen::Vector3d& point_in_world) {
    for (int c = 0; c < static_cast<int>(scene.truth.cameras.size()); ++c)
      if (const auto pixel = scene.truth.cameras[c].Project(point_in_world))
        track.observations.push_back({c, *pixel});
    scene.tracks.push_back(track);
  };
  for (int f = 0; f < frames; ++f) {
    scene.body.rotation.push_back(RotationFromAxisAngle(Eigen::Vector3d(0.1 * f, 0.2, -0.05 * f)));
    scene.body.translation.push_back(Eigen::Vector3d(0.02 * f, -0.01 * f, 1.0));
    scene.body.valid.push_back(1);
    for (int k = 0; k < 5; ++k) {
      BundleTrack track;
      track.frame = f;
      track.rigid = k;
      observe(track, scene.body.rotation[f] * scene.body.points[k] + scene.body.translation[f]);
    }
    for (int p = 0; p < 10; ++p) {
      BundleTrack track;
      track.frame = f;
      track.point = p;
      track.point_in_world = Eigen::Vector3d(free.at(f, p, 0), free.at(f, p, 1), free.at(f, p, 2));
      observe(track, track.point_in_world);
    }
  }
  return scene;
}

RigAdjustmentOptions Options(const Rig& rig) {
  RigAdjustmentOptions options;
  for (int c = 0; c < static_cast<int>(rig.cameras.size()); ++c) options.cameras.push_back(c);
  options.scale = {0, 1, 2, 3, 0.6, 10.0};
  options.loss_scale_px = 1;
  return options;
}

TEST(AdjustRig, BringsATurnedAndShiftedCameraBackAndHoldsTheGauge) {
  const Scene scene = MakeScene();
  Rig rig = scene.truth;
  Camera& moved = rig.cameras[3];
  moved.cam_from_world.rotation =
      RotationFromAxisAngle(Eigen::Vector3d(0.02, -0.01, 0.015)) * moved.cam_from_world.rotation;
  moved.cam_from_world.translation += Eigen::Vector3d(0.03, -0.02, 0.01);
  RigidBody body = scene.body;
  for (Eigen::Vector3d& p : body.points) p *= 1.1;  // the scale off by 10 %

  const auto summary = AdjustRig(Options(rig), scene.tracks, &rig, &body);
  ASSERT_TRUE(summary.ok()) << summary.status().message();
  EXPECT_EQ(summary->termination, "CONVERGENCE");
  EXPECT_LT(summary->final_cost, 1e-12);
  EXPECT_GT(summary->residual_blocks, 0);
  // The reference exactly as given (not through angle-axis and back).
  EXPECT_EQ(rig.cameras[0].cam_from_world.rotation, scene.truth.cameras[0].cam_from_world.rotation);
  EXPECT_EQ(rig.cameras[0].cam_from_world.translation,
            scene.truth.cameras[0].cam_from_world.translation);
  for (size_t c = 0; c < rig.cameras.size(); ++c) {
    EXPECT_LT(RotationAngleBetween(rig.cameras[c].cam_from_world.rotation,
                                   scene.truth.cameras[c].cam_from_world.rotation),
              1e-7)
        << c;
    EXPECT_LT((rig.cameras[c].CenterInWorld() - scene.truth.cameras[c].CenterInWorld()).norm(),
              1e-6)
        << c;
    EXPECT_EQ(rig.cameras[c].fx, scene.truth.cameras[c].fx) << "focal held";
  }
  const double length =
      (0.5 * (body.points[0] + body.points[1]) - 0.5 * (body.points[2] + body.points[3])).norm();
  EXPECT_NEAR(length, 0.6, 1e-7);
}

TEST(AdjustRig, LeavesCamerasItIsNotGivenExactlyAsTheyWere) {
  const Scene scene = MakeScene();
  Rig rig = scene.truth;
  rig.cameras[5].cam_from_world.translation += Eigen::Vector3d(0.01, 0, 0);
  const Rig input = rig;
  RigidBody body = scene.body;
  RigAdjustmentOptions options = Options(rig);
  options.cameras = {0, 1, 2, 3, 4};
  options.refine_focal = true;
  ASSERT_TRUE(AdjustRig(options, scene.tracks, &rig, &body).ok());
  EXPECT_EQ(rig.cameras[5].cam_from_world.rotation, input.cameras[5].cam_from_world.rotation);
  EXPECT_EQ(rig.cameras[5].cam_from_world.translation, input.cameras[5].cam_from_world.translation);
  EXPECT_EQ(rig.cameras[5].fx, input.cameras[5].fx);
}

TEST(AdjustRig, RefusesIndicesOutsideTheRigOrTheBodyAndLeavesBothUnchanged) {
  const Scene scene = MakeScene();
  const auto refused = [&](const RigAdjustmentOptions& options,
                           const std::vector<BundleTrack>& tracks) {
    Rig rig = scene.truth;
    RigidBody body = scene.body;
    const auto summary = AdjustRig(options, tracks, &rig, &body);
    EXPECT_EQ(rig.cameras[1].cam_from_world.translation,
              scene.truth.cameras[1].cam_from_world.translation);
    EXPECT_EQ(body.points[0], scene.body.points[0]);
    return !summary.ok() && summary.status().message().find("bundle adjustment") == 0;
  };
  const RigAdjustmentOptions good = Options(scene.truth);
  RigAdjustmentOptions o = good;
  o.reference_camera = 6;
  EXPECT_TRUE(refused(o, scene.tracks));
  o = good;
  o.cameras.push_back(-1);
  EXPECT_TRUE(refused(o, scene.tracks));
  o = good;
  o.loss_scale_px = NAN;
  EXPECT_TRUE(refused(o, scene.tracks));
  o = good;
  o.max_iterations = 0;
  EXPECT_TRUE(refused(o, scene.tracks));
  o = good;
  o.scale.b1 = 5;  // the body has 5 template points
  EXPECT_TRUE(refused(o, scene.tracks));
  o = good;
  o.scale.length = -0.6;
  EXPECT_TRUE(refused(o, scene.tracks));
  std::vector<BundleTrack> tracks = scene.tracks;
  tracks[0].observations[0].camera = 6;
  EXPECT_TRUE(refused(good, tracks));
  tracks = scene.tracks;
  tracks[0].rigid = 5;
  EXPECT_TRUE(refused(good, tracks));
  tracks = scene.tracks;
  tracks[0].frame = 8;  // a rigid track in a frame the body has no pose for
  EXPECT_TRUE(refused(good, tracks));
}

}  // namespace
}  // namespace arco::calibration
