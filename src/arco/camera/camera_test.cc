#include "arco/camera/camera.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <random>

#include "arco/camera/undistort.h"

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
  cam.cam_from_world.rotation =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1, 0.1).normalized()).toRotationMatrix();
  cam.cam_from_world.translation = Eigen::Vector3d(0.1, -0.2, 2.5);
  return cam;
}

TEST(Camera, ProjectThenUnprojectRoundTrips) {
  const Camera cam = MakeDistortedCamera();
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (int i = 0; i < 200; ++i) {
    Eigen::Vector3d p_cam(u(rng), u(rng) * 1.2, 2.0 + u(rng));
    Eigen::Vector3d p_world =
        cam.cam_from_world.rotation.transpose() * (p_cam - cam.cam_from_world.translation);
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

TEST(Camera, NewtonUndistortionMatchesTheGaussNewtonOne) {
  Camera cam = MakeDistortedCamera();
  std::mt19937 rng(7);
  // Over the whole image, including the corners where distortion is strongest.
  std::uniform_real_distribution<double> u(0, cam.width), v(0, cam.height);
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector2d pixel(u(rng), v(rng));
    const Eigen::Vector2d n = PixelToNormalizedNewton(cam, pixel);
    EXPECT_LT((n - cam.PixelToNormalized(pixel)).norm(), 1e-11);
    double xd, yd;
    cam.Distort(n.x(), n.y(), &xd, &yd);
    EXPECT_LT(Eigen::Vector2d(cam.fx * xd + cam.skew * yd + cam.cx - pixel.x(),
                              cam.fy * yd + cam.cy - pixel.y())
                  .norm(),
              1e-8);  // px
  }
  cam.distortion = Distortion();
  EXPECT_EQ(PixelToNormalizedNewton(cam, {1200, 100}), cam.PixelToNormalized({1200, 100}));
}

TEST(Camera, PointBehindCameraDoesNotProject) {
  const Camera cam = MakeDistortedCamera();
  Eigen::Vector3d behind = cam.CenterInWorld() - cam.cam_from_world.rotation.row(2).transpose();
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

namespace arco {
namespace {

TEST(Camera, UndistortPixelGivesThePinholeProjection) {
  const Camera cam = MakeDistortedCamera();
  Camera pinhole = cam;
  pinhole.distortion = {};
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d p_world =
        cam.CenterInWorld() + cam.cam_from_world.rotation.transpose() *
                                  Eigen::Vector3d(u(rng), u(rng) * 1.2, 2.0 + u(rng));
    const Eigen::Vector2d distorted = *cam.Project(p_world);
    const Eigen::Vector2d ideal = *pinhole.Project(p_world);
    EXPECT_LT((cam.UndistortPixel(distorted) - ideal).norm(), 1e-8);
  }
}

TEST(Camera, AutodiffJacobianMatchesFiniteDifferences) {
  const Camera cam = MakeDistortedCamera();
  using Jet = ceres::Jet<double, 3>;
  const Eigen::Vector3d p = cam.CenterInWorld() + cam.cam_from_world.rotation.transpose() *
                                                      Eigen::Vector3d(0.3, -0.4, 2.2);
  Jet point[3], pixel[2];
  for (int k = 0; k < 3; ++k) point[k] = Jet(p[k], k);
  ASSERT_TRUE(cam.ProjectToPixel(point, pixel));
  for (int k = 0; k < 3; ++k) {
    const double h = 1e-6;
    Eigen::Vector3d plus = p, minus = p;
    plus[k] += h;
    minus[k] -= h;
    const Eigen::Vector2d numeric = (*cam.Project(plus) - *cam.Project(minus)) / (2 * h);
    EXPECT_NEAR(pixel[0].v[k], numeric.x(), 1e-5 * std::max(1.0, std::abs(numeric.x())));
    EXPECT_NEAR(pixel[1].v[k], numeric.y(), 1e-5 * std::max(1.0, std::abs(numeric.y())));
  }
  EXPECT_NEAR(pixel[0].a, cam.Project(p)->x(), 1e-12);
}

// The closed-form derivative against Jets over many points of the image, with skew
// and all five distortion terms; the pixel equals ProjectToPixel<double> exactly.
TEST(Camera, ProjectWithJacobianMatchesAutodiff) {
  Camera cam = MakeDistortedCamera();
  cam.skew = 1.7;
  cam.fy = 2250.3;
  using Jet = ceres::Jet<double, 3>;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0), z(0.5, 4.0);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d in_camera(u(rng), u(rng), z(rng));
    const Eigen::Vector3d p =
        cam.cam_from_world.rotation.transpose() * (in_camera - cam.cam_from_world.translation);
    Jet point[3], pixel[2];
    for (int k = 0; k < 3; ++k) point[k] = Jet(p[k], k);
    ASSERT_TRUE(cam.ProjectToPixel(point, pixel));
    Eigen::Vector2d px;
    Eigen::Matrix<double, 2, 3> d;
    ASSERT_TRUE(cam.ProjectWithJacobian(p, &px, &d));
    const Eigen::Vector2d plain = *cam.Project(p);
    EXPECT_EQ(px.x(), plain.x());
    EXPECT_EQ(px.y(), plain.y());
    for (int r = 0; r < 2; ++r) {
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(d(r, k), pixel[r].v[k], 1e-9 * std::max(1.0, std::abs(pixel[r].v[k])));
      }
    }
  }
  Eigen::Vector2d px;
  Eigen::Matrix<double, 2, 3> d;
  EXPECT_FALSE(cam.ProjectWithJacobian(
      cam.CenterInWorld() - cam.cam_from_world.rotation.row(2).transpose(), &px, &d));
}

TEST(Camera, MetashapeAndOpenCvTangentialRolesAreSwapped) {
  // With only p1 set, OpenCV moves x by p2-free terms: x' = x + 2 p1 x y,
  // y' = y + p1 (r^2 + 2 y^2); Metashape's p2 does exactly this (DOMAIN.md section 4).
  Camera cam;
  cam.distortion.p1 = 0.01;
  double xd, yd;
  const double x = 0.3, y = -0.2, r2 = x * x + y * y;
  cam.Distort(x, y, &xd, &yd);
  EXPECT_DOUBLE_EQ(xd, x + 2 * 0.01 * x * y);
  EXPECT_DOUBLE_EQ(yd, y + 0.01 * (r2 + 2 * y * y));
}

}  // namespace
}  // namespace arco
