#include "arco/camera/camera.h"

#include <gtest/gtest.h>

#include <random>

namespace arco {
namespace {

Camera MakeDistortedCamera() {
  Camera cam;
  cam.width = 2300;
  cam.height = 2656;
  cam.fx = cam.fy = 2261.66;
  cam.cx = 1144.1;
  cam.cy = 1319.0;
  cam.distortion = {-0.0809, 0.0662, 0.0195, -0.00035, 0.00062};
  cam.cam_from_world_rotation =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1, 0.1).normalized()).toRotationMatrix();
  cam.cam_from_world_translation = Eigen::Vector3d(0.1, -0.2, 2.5);
  return cam;
}

TEST(Camera, ProjectThenUnprojectRoundTrips) {
  const Camera cam = MakeDistortedCamera();
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (int i = 0; i < 200; ++i) {
    Eigen::Vector3d p_cam(u(rng), u(rng) * 1.2, 2.0 + u(rng));
    Eigen::Vector3d p_world =
        cam.cam_from_world_rotation.transpose() * (p_cam - cam.cam_from_world_translation);
    auto pixel = cam.Project(p_world);
    ASSERT_TRUE(pixel.has_value());
    Eigen::Vector2d n = cam.PixelToNormalized(*pixel);
    EXPECT_NEAR(n.x(), p_cam.x() / p_cam.z(), 1e-9);
    EXPECT_NEAR(n.y(), p_cam.y() / p_cam.z(), 1e-9);
    Eigen::Vector3d ray = cam.RayInWorld(*pixel);
    Eigen::Vector3d to_point = (p_world - cam.CenterInWorld()).normalized();
    EXPECT_NEAR(ray.dot(to_point), 1.0, 1e-12);
  }
}

TEST(Camera, PointBehindCameraDoesNotProject) {
  const Camera cam = MakeDistortedCamera();
  Eigen::Vector3d behind = cam.CenterInWorld() - cam.cam_from_world_rotation.row(2).transpose();
  EXPECT_FALSE(cam.Project(behind).has_value());
}

TEST(Camera, ProjectionMatrixMatchesUndistortedProjection) {
  Camera cam = MakeDistortedCamera();
  cam.distortion = {};
  const Eigen::Vector3d p(0.1, 0.2, 0.3);
  Eigen::Vector3d h = cam.ProjectionMatrix() * p.homogeneous();
  EXPECT_TRUE(h.hnormalized().isApprox(*cam.Project(p), 1e-12));
}

}  // namespace
}  // namespace arco
