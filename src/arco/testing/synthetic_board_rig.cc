#include "arco/testing/synthetic_board_rig.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "arco/testing/look_at.h"

namespace arco::testing {

using calibration::BoardSpec;
using calibration::BoardView;
using calibration::CameraBoardViews;

SyntheticBoardRig MakeSyntheticBoardRig(const BoardSpec& board,
                                        const SyntheticBoardRigOptions& options) {
  SyntheticBoardRig rig;
  rig.truth.units = "mm";
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> uniform(-1, 1);
  std::normal_distribution<double> noise(0, options.noise_px);
  const Eigen::Vector3d centre(0, 0, 1200);
  for (int c = 0; c < options.num_cameras; ++c) {
    const double angle = 2 * M_PI * c / options.num_cameras;
    Camera cam;
    cam.name = "cam" + std::to_string(c);
    cam.width = options.width;
    cam.height = options.height;
    cam.fx = 1400 + 20 * c;
    cam.fy = cam.fx * (1 + 0.001 * uniform(rng));
    cam.cx = (options.width - 1) / 2.0 + 15 * uniform(rng);
    cam.cy = (options.height - 1) / 2.0 + 10 * uniform(rng);
    cam.distortion.k1 = -0.12 + 0.02 * uniform(rng);
    cam.distortion.k2 = 0.08 + 0.02 * uniform(rng);
    cam.distortion.k3 = -0.01;
    cam.distortion.p1 = 0.0005 * uniform(rng);
    cam.distortion.p2 = 0.0005 * uniform(rng);
    const Eigen::Vector3d position(options.ring_radius_mm * std::cos(angle),
                                   options.ring_radius_mm * std::sin(angle),
                                   options.camera_height_mm + 100 * uniform(rng));
    const Eigen::Vector3d target =
        centre + Eigen::Vector3d(100 * uniform(rng), 100 * uniform(rng), 0);
    cam.cam_from_world.rotation = CamFromWorldLookingAt(position, target);
    cam.cam_from_world.translation = -cam.cam_from_world.rotation * position;
    rig.truth.cameras.push_back(cam);
    CameraBoardViews views;
    views.camera = cam.name;
    views.source = "synthetic " + cam.name;
    views.width = cam.width;
    views.height = cam.height;
    views.frames_read = options.num_frames;
    rig.views.push_back(views);
  }
  const std::vector<Eigen::Vector3d> points = board.PointsInBoard();
  const Eigen::Vector3d board_centre =
      Eigen::Vector3d(
          (board.inner_cols - 1) * board.square_mm, (board.inner_rows - 1) * board.square_mm, 0) /
      2;
  for (int f = 0; f < options.num_frames; ++f) {
    // The board faces an azimuth sweeping twice round the ring, tilted and turned a little.
    const double azimuth = 4 * M_PI * f / options.num_frames + 0.3 * uniform(rng);
    const Eigen::Vector3d normal(std::cos(azimuth), std::sin(azimuth), 0.35 * uniform(rng));
    // Board frame: z into the board (away from the cameras that see it), x along the rows.
    const Eigen::Vector3d z = -normal.normalized();
    const Eigen::Vector3d x0 = Eigen::Vector3d::UnitZ().cross(z).normalized();
    const Eigen::Vector3d y0 = z.cross(x0);
    const double roll = 0.5 * uniform(rng);
    Eigen::Matrix3d world_from_board_rotation;
    world_from_board_rotation.col(0) = std::cos(roll) * x0 + std::sin(roll) * y0;
    world_from_board_rotation.col(1) = -std::sin(roll) * x0 + std::cos(roll) * y0;
    world_from_board_rotation.col(2) = z;
    const Eigen::Vector3d position =
        centre + Eigen::Vector3d(1300 * uniform(rng), 1300 * uniform(rng), 500 * uniform(rng));
    Eigen::Isometry3d world_from_board = Eigen::Isometry3d::Identity();
    world_from_board.linear() = world_from_board_rotation;
    world_from_board.translation() = position - world_from_board_rotation * board_centre;
    rig.world_from_board.push_back(world_from_board);
    for (int c = 0; c < options.num_cameras; ++c) {
      const Camera& cam = rig.truth.cameras[c];
      const Eigen::Vector3d to_camera = (cam.CenterInWorld() - position).normalized();
      if (to_camera.dot(normal.normalized()) < std::cos(options.max_view_angle_deg * M_PI / 180))
        continue;
      BoardView view;
      view.frame = f;
      bool inside = true;
      for (int id = 0; id < board.num_points() && inside; ++id) {
        const auto pixel = cam.Project(world_from_board * points[id]);
        inside = pixel && pixel->x() > 10 && pixel->y() > 10 && pixel->x() < cam.width - 11 &&
                 pixel->y() < cam.height - 11;
        if (!inside) break;
        view.point_ids.push_back(id);
        view.corners_px.push_back(*pixel + Eigen::Vector2d(noise(rng), noise(rng)));
      }
      if (inside) rig.views[c].views.push_back(std::move(view));
    }
  }
  return rig;
}

BoardRenderer::BoardRenderer(const BoardSpec& board, const Camera& camera, int supersample)
    : board_(board), camera_(camera), supersample_(supersample) {
  const int w = camera.width * supersample, h = camera.height * supersample;
  rays_.resize(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Eigen::Vector2d pixel((x + 0.5) / supersample - 0.5, (y + 0.5) / supersample - 0.5);
      rays_[static_cast<size_t>(y) * w + x] = camera.PixelToNormalized(pixel).cast<float>();
    }
}

media::Image BoardRenderer::Render(const Eigen::Isometry3d& world_from_board) const {
  const Camera& camera = camera_;
  const BoardSpec& board = board_;
  media::Image image;
  image.width = camera.width;
  image.height = camera.height;
  image.format = media::PixelFormat::kGray8;
  image.pixels.assign(static_cast<size_t>(image.width) * image.height, 128);
  const Eigen::Isometry3d board_from_world = world_from_board.inverse();
  const Eigen::Matrix3d board_from_cam =
      board_from_world.linear() * camera.cam_from_world.rotation.transpose();
  const Eigen::Vector3d origin = board_from_world * camera.CenterInWorld();
  const double s = board.square_mm;
  // The squares span [-s, inner_cols * s] x [-s, inner_rows * s] (corner ids at multiples
  // of s); a white margin of one square around them.
  const double x_min = -2 * s, x_max = (board.inner_cols + 1) * s;
  const double y_min = -2 * s, y_max = (board.inner_rows + 1) * s;
  // Bounding box of the board in the image, to skip the background.
  double u0 = camera.width, u1 = 0, v0 = camera.height, v1 = 0;
  for (double bx : {x_min, x_max})
    for (double by : {y_min, y_max}) {
      const auto p = camera.Project(world_from_board * Eigen::Vector3d(bx, by, 0));
      if (!p) return image;
      u0 = std::min(u0, p->x()), u1 = std::max(u1, p->x());
      v0 = std::min(v0, p->y()), v1 = std::max(v1, p->y());
    }
  const int x_begin = std::clamp(static_cast<int>(u0) - 20, 0, camera.width);
  const int x_end = std::clamp(static_cast<int>(u1) + 20, 0, camera.width);
  const int y_begin = std::clamp(static_cast<int>(v0) - 20, 0, camera.height);
  const int y_end = std::clamp(static_cast<int>(v1) + 20, 0, camera.height);
  const int sub = supersample_;
  const int row = camera.width * sub;
  for (int v = y_begin; v < y_end; ++v)
    for (int u = x_begin; u < x_end; ++u) {
      int sum = 0;
      for (int sy = 0; sy < sub; ++sy)
        for (int sx = 0; sx < sub; ++sx) {
          const Eigen::Vector2f& n = rays_[static_cast<size_t>(v * sub + sy) * row + u * sub + sx];
          const Eigen::Vector3d ray = board_from_cam * Eigen::Vector3d(n.x(), n.y(), 1);
          int value = 128;
          if (std::abs(ray.z()) > 1e-12) {
            const double t = -origin.z() / ray.z();
            const double hx = origin.x() + t * ray.x(), hy = origin.y() + t * ray.y();
            if (t > 0 && hx >= x_min && hx <= x_max && hy >= y_min && hy <= y_max) {
              value = 255;
              if (hx >= -s && hx <= board.inner_cols * s && hy >= -s &&
                  hy <= board.inner_rows * s) {
                const int i = static_cast<int>(std::floor(hx / s)) + 1;
                const int j = static_cast<int>(std::floor(hy / s)) + 1;
                value = (i + j) % 2 == 0 ? 20 : 235;
              }
            }
          }
          sum += value;
        }
      image.pixels[static_cast<size_t>(v) * image.width + u] =
          static_cast<uint8_t>(sum / (sub * sub));
    }
  return image;
}

}  // namespace arco::testing
