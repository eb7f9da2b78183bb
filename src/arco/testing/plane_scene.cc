#include "arco/testing/plane_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "arco/camera/calibration_io.h"
#include "arco/media/video_writer.h"
#include "arco/synth/random.h"
#include "arco/testing/look_at.h"
#include "arco/util/file_io.h"
#include "arco/util/json_io.h"
#include "arco/util/output_set.h"
#include "arco/util/parallel.h"

namespace arco::testing {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string ToString(double value) {
  std::string s = std::to_string(value);
  s.erase(s.find_last_not_of('0') + 1);
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s;
}

// Texture pixel of plane point (X, Y) as an affine map: u = s_x X + o_x, v = s_y Y + o_y.
Eigen::Matrix3d PlaneToTextureMatrix(const PlaneTexture& texture) {
  const double sx = texture.image.width / texture.width_mm;
  const double sy = texture.image.height / texture.height_mm;
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  m(0, 0) = sx;
  m(1, 1) = sy;
  m(0, 2) = 0.5 * texture.image.width - 0.5;
  m(1, 2) = 0.5 * texture.image.height - 0.5;
  return m;
}

// Bilinear sample of `texture` at (u, v) (edge pixels clamped), converted to
// `out_channels` channels, times `weight`, added to acc.
void AddBilinear(
    const media::Image& texture, double u, double v, float weight, int out_channels, float* acc) {
  const int w = texture.width, h = texture.height, tc = texture.channels();
  u = std::clamp(u, 0.0, double(w - 1));
  v = std::clamp(v, 0.0, double(h - 1));
  const int u0 = std::min(static_cast<int>(u), w - 1), v0 = std::min(static_cast<int>(v), h - 1);
  const int u1 = std::min(u0 + 1, w - 1), v1 = std::min(v0 + 1, h - 1);
  const float fu = static_cast<float>(u - u0), fv = static_cast<float>(v - v0);
  const uint8_t* r0 = texture.row(v0);
  const uint8_t* r1 = texture.row(v1);
  float value[3];
  for (int c = 0; c < tc; ++c) {
    const float top = r0[u0 * tc + c] + fu * (r0[u1 * tc + c] - r0[u0 * tc + c]);
    const float bottom = r1[u0 * tc + c] + fu * (r1[u1 * tc + c] - r1[u0 * tc + c]);
    value[c] = weight * (top + fv * (bottom - top));
  }
  if (tc == out_channels) {
    for (int c = 0; c < tc; ++c) acc[c] += value[c];
  } else if (tc == 1) {  // gray texture, RGB output
    for (int c = 0; c < 3; ++c) acc[c] += value[0];
  } else {  // RGB texture, gray output: BT.601 luma
    acc[0] += 0.299f * value[0] + 0.587f * value[1] + 0.114f * value[2];
  }
}

// Half-size level of `image`: texel i averages texels 2i and 2i + 1 (the last one
// clamped on odd sides) in both directions, so level texel centres sit at
// (i + 0.5) * 2 - 0.5 of the finer level.
media::Image HalveImage(const media::Image& image) {
  const int w = std::max(1, (image.width + 1) / 2), h = std::max(1, (image.height + 1) / 2);
  const int c = image.channels();
  media::Image half = media::MakeImage(w, h, image.format);
  for (int y = 0; y < h; ++y) {
    const uint8_t* r0 = image.row(std::min(2 * y, image.height - 1));
    const uint8_t* r1 = image.row(std::min(2 * y + 1, image.height - 1));
    uint8_t* out = half.row(y);
    for (int x = 0; x < w; ++x) {
      const int x0 = std::min(2 * x, image.width - 1), x1 = std::min(2 * x + 1, image.width - 1);
      for (int k = 0; k < c; ++k) {
        out[x * c + k] = static_cast<uint8_t>(
            (r0[x0 * c + k] + r0[x1 * c + k] + r1[x0 * c + k] + r1[x1 * c + k] + 2) / 4);
      }
    }
  }
  return half;
}

}  // namespace

void BuildMipmaps(PlaneTexture* texture) {
  texture->mipmaps.clear();
  const media::Image* level = &texture->image;
  while (level->width > 1 || level->height > 1) {
    texture->mipmaps.push_back(HalveImage(*level));
    level = &texture->mipmaps.back();
  }
}

void PlaneTexture::Check() const {
  if (image.empty() || image.width < 1 || image.height < 1 ||
      image.pixels.size() != image.row_bytes() * static_cast<size_t>(image.height)) {
    throw std::invalid_argument("PlaneTexture: empty or malformed image");
  }
  if (!mipmaps.empty() && (mipmaps[0].width != std::max(1, (image.width + 1) / 2) ||
                           mipmaps[0].height != std::max(1, (image.height + 1) / 2) ||
                           mipmaps[0].format != image.format)) {
    throw std::invalid_argument("PlaneTexture: mipmaps do not match the image (call BuildMipmaps)");
  }
  if (!(width_mm > 0) || !(height_mm > 0) || !std::isfinite(width_mm) ||
      !std::isfinite(height_mm)) {
    throw std::invalid_argument("PlaneTexture: width_mm and height_mm must be positive, got " +
                                ToString(width_mm) + " x " + ToString(height_mm));
  }
}

Eigen::Vector2d TexturePixelToPlane(const PlaneTexture& texture,
                                    const Eigen::Vector2d& texture_px) {
  return {
      (texture_px.x() + 0.5) * texture.width_mm / texture.image.width - 0.5 * texture.width_mm,
      (texture_px.y() + 0.5) * texture.height_mm / texture.image.height - 0.5 * texture.height_mm};
}

Eigen::Vector2d PlaneToTexturePixel(const PlaneTexture& texture,
                                    const Eigen::Vector2d& point_in_plane) {
  const Eigen::Vector3d uv = PlaneToTextureMatrix(texture) * point_in_plane.homogeneous();
  return uv.head<2>();
}

Eigen::Vector3d PlaneToWorld(const Rigid3d& world_from_plane,
                             const Eigen::Vector2d& point_in_plane) {
  return world_from_plane * Eigen::Vector3d(point_in_plane.x(), point_in_plane.y(), 0.0);
}

double InvertibleRadius(const Distortion& d) {
  // d/dr [r (1 + k1 r^2 + k2 r^4 + k3 r^6)] = 1 + 3 k1 r^2 + 5 k2 r^4 + 7 k3 r^6: the first
  // zero (scanned to r = 10, about 84 degrees off axis; then refined by bisection).
  auto slope = [&](double r) {
    const double r2 = r * r;
    return 1 + r2 * (3 * d.k1 + r2 * (5 * d.k2 + r2 * 7 * d.k3));
  };
  constexpr double kStep = 1e-3, kMax = 10;
  for (double r = kStep; r <= kMax; r += kStep) {
    if (slope(r) <= 0) {
      double lo = r - kStep, hi = r;
      for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (slope(mid) > 0 ? lo : hi) = mid;
      }
      return lo;
    }
  }
  return std::numeric_limits<double>::infinity();
}

std::optional<Eigen::Vector2d> ProjectPlanePoint(const Camera& camera,
                                                 const Rigid3d& world_from_plane,
                                                 const PlaneTexture& texture,
                                                 const Eigen::Vector2d& texture_px) {
  const Eigen::Vector3d point_in_world =
      PlaneToWorld(world_from_plane, TexturePixelToPlane(texture, texture_px));
  const Eigen::Vector3d p = camera.PointInCamera(point_in_world);
  if (!(p.z() > 0)) return std::nullopt;
  if (Eigen::Vector2d(p.x() / p.z(), p.y() / p.z()).norm() >= InvertibleRadius(camera.distortion)) {
    return std::nullopt;
  }
  return camera.Project(point_in_world);
}

bool InImage(const Camera& camera, const Eigen::Vector2d& pixel) {
  return pixel.x() >= -0.5 && pixel.x() < camera.width - 0.5 && pixel.y() >= -0.5 &&
         pixel.y() < camera.height - 0.5;
}

Status PlaneRenderOptions::Validate() const {
  if (supersampling < 1 || supersampling > 8) {
    return Status::Error("PlaneRenderOptions: supersampling must be in [1, 8], got " +
                         std::to_string(supersampling));
  }
  if (!(max_undistortion_error_px > 0) || !std::isfinite(max_undistortion_error_px)) {
    return Status::Error("PlaneRenderOptions: max_undistortion_error_px must be > 0");
  }
  if (threads < 0 || threads > 256) {
    return Status::Error("PlaneRenderOptions: threads must be in [0, 256]");
  }
  return Status::Ok();
}

PlaneRenderer::PlaneRenderer(const Camera& camera, const PlaneRenderOptions& options)
    : camera_(camera), options_(options) {
  if (Status valid = options.Validate(); !valid.ok()) throw std::invalid_argument(valid.message());
  if (camera.width < 1 || camera.height < 1 || !(camera.fx > 0) || !(camera.fy > 0)) {
    throw std::invalid_argument("PlaneRenderer: camera '" + camera.name +
                                "' has no image size or focal length");
  }
  const int s = options.supersampling;
  const int64_t sample_width = int64_t(camera.width) * s, sample_rows = int64_t(camera.height) * s;
  rays_.assign(sample_width * sample_rows, Eigen::Vector2d::Constant(std::nan("")));
  const double max_radius = InvertibleRadius(camera.distortion);
  std::vector<int64_t> invalid(sample_rows, 0);
  std::vector<double> max_error(sample_rows, 0.0);
  ParallelFor(sample_rows, options.threads, [&](int64_t j, int) {
    const double y = (j + 0.5) / s - 0.5;
    for (int64_t i = 0; i < sample_width; ++i) {
      const Eigen::Vector2d pixel((i + 0.5) / s - 0.5, y);
      const Eigen::Vector2d n = camera_.PixelToNormalized(pixel);
      // The round trip through the forward model is the undistortion's accuracy.
      double xd, yd;
      camera_.Distort(n.x(), n.y(), &xd, &yd);
      const Eigen::Vector2d back(camera_.fx * xd + camera_.skew * yd + camera_.cx,
                                 camera_.fy * yd + camera_.cy);
      const double error = (back - pixel).norm();
      if (!n.allFinite() || !(n.norm() < max_radius) ||
          !(error <= options_.max_undistortion_error_px)) {
        ++invalid[j];
        continue;
      }
      max_error[j] = std::max(max_error[j], error);
      rays_[j * sample_width + i] = n;
    }
  });
  for (int64_t j = 0; j < sample_rows; ++j) {
    invalid_samples_ += invalid[j];
    max_error_px_ = std::max(max_error_px_, max_error[j]);
  }
}

void PlaneRenderer::Render(const Rigid3d& world_from_plane,
                           const PlaneTexture& texture,
                           const media::Image& background,
                           media::Image* out) const {
  texture.Check();
  if (background.width != camera_.width || background.height != camera_.height ||
      background.pixels.size() != background.row_bytes() * static_cast<size_t>(background.height)) {
    throw std::invalid_argument(
        "PlaneRenderer::Render: the background is " + std::to_string(background.width) + "x" +
        std::to_string(background.height) + ", camera '" + camera_.name + "' " +
        std::to_string(camera_.width) + "x" + std::to_string(camera_.height));
  }
  *out = background;

  // cam_from_plane; plane point (X, Y, 0) -> X r1 + Y r2 + t = H (X, Y, 1), so the ray
  // (x, y, 1) meets the plane at H^-1 (x, y, 1) = (X, Y, 1) / depth: depth > 0 in front.
  const Eigen::Matrix3d r = camera_.cam_from_world.rotation * world_from_plane.RotationMatrix();
  const Eigen::Vector3d t = camera_.cam_from_world.rotation * world_from_plane.translation +
                            camera_.cam_from_world.translation;
  Eigen::Matrix3d h;
  h << r.col(0), r.col(1), t;
  // det H = t . r3: zero when the camera centre lies in the plane (seen edge-on),
  // positive when it is on the plane's -z (front) side.
  const double det = t.dot(r.col(2));
  if (std::abs(det) <= 1e-12 * std::max(1.0, t.norm())) return;
  if (!options_.two_sided && det < 0) return;
  const Eigen::Matrix3d to_texture = PlaneToTextureMatrix(texture) * h.inverse();

  const int s = options_.supersampling;
  const int64_t sample_width = int64_t(camera_.width) * s;
  const int channels = out->channels();
  const double u_max = texture.image.width - 0.5, v_max = texture.image.height - 0.5;
  const float inv_samples = 1.0f / (s * s);
  // Level k of the pyramid (texel = 2^k texture pixels); level 0 only without mipmaps.
  std::vector<media::Image> built;
  std::vector<const media::Image*> levels = {&texture.image};
  if (options_.mipmap) {
    const std::vector<media::Image>* mipmaps = &texture.mipmaps;
    if (mipmaps->empty()) {
      PlaneTexture copy;
      copy.image = texture.image;
      BuildMipmaps(&copy);
      built = std::move(copy.mipmaps);
      mipmaps = &built;
    }
    for (const media::Image& level : *mipmaps) levels.push_back(&level);
  }
  const double inv_fx = 1.0 / camera_.fx, inv_fy = 1.0 / camera_.fy;
  ParallelFor(
      camera_.height,
      options_.threads,
      [&](int64_t y, int) {
        uint8_t* row = out->row(static_cast<int>(y));
        for (int x = 0; x < camera_.width; ++x) {
          float acc[3] = {0, 0, 0};
          int plane_samples = 0;
          for (int sj = 0; sj < s; ++sj) {
            const Eigen::Vector2d* rays = &rays_[(y * s + sj) * sample_width + int64_t(x) * s];
            for (int si = 0; si < s; ++si) {
              const Eigen::Vector2d& n = rays[si];
              if (std::isnan(n.x())) continue;
              const Eigen::Vector3d q = to_texture * Eigen::Vector3d(n.x(), n.y(), 1.0);
              if (!(q.z() > 0)) continue;
              const double u = q.x() / q.z(), v = q.y() / q.z();
              if (!(u >= -0.5 && u <= u_max && v >= -0.5 && v <= v_max)) continue;
              ++plane_samples;
              if (levels.size() == 1) {
                AddBilinear(texture.image, u, v, 1.0f, channels, acc);
                continue;
              }
              // Texels per sample from the homography's Jacobian (the lens's own
              // Jacobian, a few per cent, is ignored for the choice of level).
              const double du_dx = (to_texture(0, 0) - u * to_texture(2, 0)) / q.z();
              const double dv_dx = (to_texture(1, 0) - v * to_texture(2, 0)) / q.z();
              const double du_dy = (to_texture(0, 1) - u * to_texture(2, 1)) / q.z();
              const double dv_dy = (to_texture(1, 1) - v * to_texture(2, 1)) / q.z();
              const double texels =
                  std::max(std::hypot(du_dx, dv_dx) * inv_fx, std::hypot(du_dy, dv_dy) * inv_fy) /
                  s;
              if (!(texels > 1)) {
                AddBilinear(texture.image, u, v, 1.0f, channels, acc);
                continue;
              }
              // Trilinear: the two levels around log2(texels), blended.
              const double lambda = std::min(std::log2(texels), double(levels.size() - 1));
              const int l0 = std::min(static_cast<int>(lambda), int(levels.size()) - 1);
              const int l1 = std::min(l0 + 1, int(levels.size()) - 1);
              const float t = static_cast<float>(lambda - l0);
              const double scale0 = 1.0 / (1 << l0), scale1 = 1.0 / (1 << l1);
              AddBilinear(*levels[l0],
                          (u + 0.5) * scale0 - 0.5,
                          (v + 0.5) * scale0 - 0.5,
                          1.0f - t,
                          channels,
                          acc);
              if (t > 0) {
                AddBilinear(*levels[l1],
                            (u + 0.5) * scale1 - 0.5,
                            (v + 0.5) * scale1 - 0.5,
                            t,
                            channels,
                            acc);
              }
            }
          }
          if (plane_samples == 0) continue;  // background as copied
          const int background_samples = s * s - plane_samples;
          for (int c = 0; c < channels; ++c) {
            const float value =
                (acc[c] + background_samples * float(row[x * channels + c])) * inv_samples;
            row[x * channels + c] = static_cast<uint8_t>(std::clamp(std::lround(value), 0L, 255L));
          }
        }
      },
      /*chunk=*/4);
}

media::Image RenderView(const Camera& camera,
                        const Rigid3d& world_from_plane,
                        const PlaneTexture& texture,
                        const media::Image& background,
                        const PlaneRenderOptions& options) {
  media::Image out;
  PlaneRenderer(camera, options).Render(world_from_plane, texture, background, &out);
  return out;
}

media::Image MakeSolidImage(int width,
                            int height,
                            media::PixelFormat format,
                            std::array<uint8_t, 3> rgb) {
  media::Image image = media::MakeImage(width, height, format);
  const int channels = image.channels();
  for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = rgb[i % channels];
  return image;
}

Status PlaneRigOptions::Validate() const {
  auto fail = [](const std::string& what) { return Status::Error("PlaneRigOptions: " + what); };
  if (cameras < 1 || cameras > 256) return fail("cameras must be in [1, 256]");
  if (width < 16 || height < 16 || width > 16384 || height > 16384) {
    return fail("width and height must be in [16, 16384]");
  }
  if (focal_px < 0 || !std::isfinite(focal_px)) return fail("focal_px must be >= 0");
  if (!(distance_mm > 0) || !std::isfinite(distance_mm)) return fail("distance_mm must be > 0");
  if (!(arc_deg >= 0 && arc_deg <= 360)) return fail("arc_deg must be in [0, 360]");
  if (!(height_mm >= 0) || !std::isfinite(height_mm)) return fail("height_mm must be >= 0");
  if (!(distortion >= 0 && distortion <= 3)) return fail("distortion must be in [0, 3]");
  return Status::Ok();
}

PlaneScene DetectPlaneScene(const media::Image& photo) {
  constexpr double kPhotoMmPerPx = 0.778;
  PlaneScene scene;
  scene.texture.image = photo;
  scene.texture.width_mm = photo.width * kPhotoMmPerPx;
  scene.texture.height_mm = photo.height * kPhotoMmPerPx;
  BuildMipmaps(&scene.texture);
  PlaneRigOptions rig;
  rig.cameras = 8;
  rig.width = 1152;
  rig.height = 1328;
  rig.focal_px = 1130;
  rig.distance_mm = 2500;
  rig.arc_deg = 100;
  scene.rig = MakePlaneRig(rig);
  PlaneMotionOptions motion;
  motion.frames = 12;
  motion.fps_hz = 30;
  motion.max_translation_mm = 150;
  motion.max_rotation_deg = 10;
  scene.world_from_plane = MakePlaneMotion(motion);
  scene.fps = {30, 1};
  return scene;
}

Rig MakePlaneRig(const PlaneRigOptions& o) {
  if (Status valid = o.Validate(); !valid.ok()) throw std::invalid_argument(valid.message());
  Rig rig;
  rig.units = "mm";
  const double focal = o.focal_px > 0 ? o.focal_px : o.width;
  for (int i = 0; i < o.cameras; ++i) {
    synth::Rng rng = synth::Rng::Stream(o.seed, i);
    Camera cam;
    cam.name = "cam" + std::to_string(i);
    cam.width = o.width;
    cam.height = o.height;
    cam.fx = focal * rng.Uniform(0.97, 1.03);
    cam.fy = cam.fx * rng.Uniform(0.998, 1.002);
    const double shift = 0.01 * o.width;
    cam.cx = 0.5 * o.width - 0.5 + rng.Uniform(-shift, shift);
    cam.cy = 0.5 * o.height - 0.5 + rng.Uniform(-shift, shift);
    cam.distortion.k1 = o.distortion * rng.Uniform(-0.09, 0.03);
    cam.distortion.k2 = o.distortion * rng.Uniform(-0.02, 0.08);
    cam.distortion.k3 = o.distortion * rng.Uniform(-0.01, 0.01);
    cam.distortion.p1 = o.distortion * rng.Uniform(-0.002, 0.002);
    cam.distortion.p2 = o.distortion * rng.Uniform(-0.002, 0.002);

    const double angle =
        o.cameras == 1 ? 0.0 : (-0.5 * o.arc_deg + o.arc_deg * i / (o.cameras - 1)) * kPi / 180;
    const double height = (i % 2 == 0 ? -1 : 1) * o.height_mm * rng.Uniform(0.5, 1.0);
    const Eigen::Vector3d center(
        o.distance_mm * std::sin(angle), -o.distance_mm * std::cos(angle), height);
    const Eigen::Vector3d target(rng.Uniform(-50, 50), 0.0, rng.Uniform(-50, 50));
    const Eigen::Matrix3d upright = CamFromWorldLookingAt(center, target);
    const Eigen::Vector3d x0 = upright.row(0).transpose();
    const Eigen::Vector3d y0 = upright.row(1).transpose();
    const Eigen::Vector3d z = upright.row(2).transpose();
    const double roll = rng.Uniform(-3, 3) * kPi / 180;
    const Eigen::Vector3d x = std::cos(roll) * x0 + std::sin(roll) * y0;
    const Eigen::Vector3d y = z.cross(x);
    Eigen::Matrix3d rotation;
    rotation.row(0) = x.transpose();
    rotation.row(1) = y.transpose();
    rotation.row(2) = z.transpose();
    cam.cam_from_world.rotation = rotation;
    cam.cam_from_world.translation = -rotation * center;
    rig.cameras.push_back(cam);
  }
  return rig;
}

Rigid3d PlaneRestPose() {
  Eigen::Matrix3d rotation;
  rotation << 1, 0, 0,  //
      0, 0, 1,          //
      0, -1, 0;         // columns: plane x, y, z in the world
  return Rigid3d(rotation, Eigen::Vector3d::Zero());
}

Status PlaneMotionOptions::Validate() const {
  auto fail = [](const std::string& what) { return Status::Error("PlaneMotionOptions: " + what); };
  if (frames < 1 || frames > 1000000) return fail("frames must be in [1, 1000000]");
  if (!(fps_hz > 0) || !std::isfinite(fps_hz)) return fail("fps_hz must be > 0");
  if (!(max_translation_mm >= 0) || !std::isfinite(max_translation_mm)) {
    return fail("max_translation_mm must be >= 0");
  }
  if (!(max_rotation_deg >= 0 && max_rotation_deg <= 90)) {
    return fail("max_rotation_deg must be in [0, 90]");
  }
  return Status::Ok();
}

std::vector<Rigid3d> MakePlaneMotion(const PlaneMotionOptions& o) {
  if (Status valid = o.Validate(); !valid.ok()) throw std::invalid_argument(valid.message());
  struct Wave {
    double amplitude[3], frequency_hz[3], phase[3];
  };
  Wave waves[6];
  for (int k = 0; k < 6; ++k) {
    synth::Rng rng = synth::Rng::Stream(o.seed, 1000 + k);
    double sum = 0;
    for (int j = 0; j < 3; ++j) {
      waves[k].amplitude[j] = rng.Uniform(0.2, 1.0);
      waves[k].frequency_hz[j] = rng.Uniform(0.1, 0.7);
      waves[k].phase[j] = rng.Uniform(0, 2 * kPi);
      sum += waves[k].amplitude[j];
    }
    const double max = k < 3 ? o.max_translation_mm : o.max_rotation_deg * kPi / 180;
    for (double& a : waves[k].amplitude) a *= max / sum;
  }
  const Rigid3d rest = PlaneRestPose();
  std::vector<Rigid3d> poses;
  poses.reserve(o.frames);
  for (int f = 0; f < o.frames; ++f) {
    const double time_s = f / o.fps_hz;
    double value[6];
    for (int k = 0; k < 6; ++k) {
      value[k] = 0;
      for (int j = 0; j < 3; ++j) {
        value[k] += waves[k].amplitude[j] *
                    std::sin(2 * kPi * waves[k].frequency_hz[j] * time_s + waves[k].phase[j]);
      }
    }
    const Eigen::Quaterniond motion = Eigen::AngleAxisd(value[5], Eigen::Vector3d::UnitZ()) *
                                      Eigen::AngleAxisd(value[4], Eigen::Vector3d::UnitY()) *
                                      Eigen::AngleAxisd(value[3], Eigen::Vector3d::UnitX());
    poses.emplace_back(motion * rest.rotation,
                       rest.translation + Eigen::Vector3d(value[0], value[1], value[2]));
  }
  return poses;
}

Status WritePlaneScene(const PlaneScene& scene,
                       const std::string& folder,
                       const PlaneSceneWriteOptions& options,
                       Progress& progress) {
  auto fail = [&](const std::string& what) { return Status::Error(folder + ": " + what); };
  ARCO_RETURN_IF_ERROR(options.render.Validate());
  if (options.threads < 0 || options.threads > 256) {
    return Status::Error("PlaneSceneWriteOptions: threads must be in [0, 256]");
  }
  if (scene.rig.cameras.empty()) return fail("the scene has no cameras");
  if (scene.world_from_plane.empty()) return fail("the scene has no frames");
  try {
    scene.texture.Check();
  } catch (const std::invalid_argument& e) {
    return fail(e.what());
  }
  if (!scene.backgrounds.empty()) {
    if (scene.backgrounds.size() != scene.rig.cameras.size()) {
      return fail("backgrounds: " + std::to_string(scene.backgrounds.size()) + " images for " +
                  std::to_string(scene.rig.cameras.size()) + " cameras");
    }
    for (size_t c = 0; c < scene.backgrounds.size(); ++c) {
      const media::Image& b = scene.backgrounds[c];
      const Camera& cam = scene.rig.cameras[c];
      if (b.format != media::PixelFormat::kRgb8 || b.width != cam.width || b.height != cam.height ||
          b.pixels.size() != b.row_bytes() * size_t(b.height)) {
        return fail("the background of camera " + cam.name + " must be an RGB8 image of " +
                    std::to_string(cam.width) + "x" + std::to_string(cam.height));
      }
    }
  }
  for (const Camera& cam : scene.rig.cameras) {
    if (cam.name.empty() || cam.name.find_first_of("/\\") != std::string::npos ||
        cam.name[0] == '.') {
      return fail("camera name '" + cam.name + "' cannot name a video file");
    }
  }
  ARCO_ASSIGN_OR_RETURN(const std::string calibration_json, WriteArcoJson(scene.rig));
  PlaneTexture texture = scene.texture;  // with its mipmaps, built once
  if (options.render.mipmap && texture.mipmaps.empty()) BuildMipmaps(&texture);

  OutputSet outputs;
  FolderReplace replace;
  replace.overwrite = options.overwrite;
  replace.marker = "truth.json";
  replace.kind = "plane scene";
  replace.option = "overwrite";
  ARCO_ASSIGN_OR_RETURN(const std::string tmp, outputs.AddFolder(folder, replace));
  ARCO_RETURN_IF_ERROR(AtomicWriteFile(JoinPath(tmp, "calibration.json"), calibration_json));
  ARCO_RETURN_IF_ERROR(MakeDirectories(JoinPath(tmp, "videos")));

  const int frames = static_cast<int>(scene.world_from_plane.size());
  progress.StartStage(1, 1, "render");
  progress.SetTotal(int64_t(frames) * scene.rig.cameras.size());
  Json videos = Json::array();  // in the rig's order
  for (const Camera& cam : scene.rig.cameras) {
    videos.push_back({{"camera", cam.name}, {"path", "videos/" + cam.name + options.extension}});
  }
  // One camera per work item: its renderer, its video; the first failing camera (in
  // the rig's order) is reported.
  auto write_camera = [&](size_t index) -> Status {
    const Camera& cam = scene.rig.cameras[index];
    media::VideoWriterOptions writer_options;
    writer_options.container = options.container;
    writer_options.codec = options.codec;
    writer_options.width = cam.width;
    writer_options.height = cam.height;
    writer_options.fps = scene.fps;
    ARCO_ASSIGN_OR_RETURN(
        media::VideoWriter writer,
        media::VideoWriter::Open(JoinPath(tmp, "videos/" + cam.name + options.extension),
                                 writer_options));
    const PlaneRenderer renderer(cam, options.render);
    const media::Image background =
        scene.backgrounds.empty()
            ? MakeSolidImage(cam.width, cam.height, media::PixelFormat::kRgb8, scene.background_rgb)
            : scene.backgrounds[index];
    media::Image frame;
    for (int f = 0; f < frames; ++f) {
      renderer.Render(scene.world_from_plane[f], texture, background, &frame);
      ARCO_RETURN_IF_ERROR(writer.Write(frame));
      progress.Advance(1);
    }
    return writer.Close();
  };
  std::vector<Status> results(scene.rig.cameras.size(), Status::Ok());
  ParallelFor(
      static_cast<int64_t>(scene.rig.cameras.size()),
      options.threads,
      [&](int64_t c, int) { results[c] = write_camera(static_cast<size_t>(c)); },
      /*chunk=*/1);
  for (const Status& result : results) ARCO_RETURN_IF_ERROR(result);

  Json truth;
  truth["format"] = "arco-plane-scene";
  truth["version"] = 1;
  truth["units"] = "mm";
  truth["plane_frame"] =
      "origin at the texture centre; x along texture rows (right), y down its columns, "
      "z = x cross y; texture pixel centres at (u + 0.5) * width_mm / width_px - width_mm / 2";
  truth["texture"] = {{"width_px", scene.texture.image.width},
                      {"height_px", scene.texture.image.height},
                      {"width_mm", scene.texture.width_mm},
                      {"height_mm", scene.texture.height_mm}};
  truth["fps"] = {scene.fps.num, scene.fps.den};
  truth["calibration"] = "calibration.json";
  truth["videos"] = videos;
  Json poses = Json::array();
  for (const Rigid3d& pose : scene.world_from_plane) {
    const Eigen::Matrix3d r = pose.RotationMatrix();
    Json rotation = Json::array();
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) rotation.push_back(r(i, j));
    }
    poses.push_back({{"R", rotation},
                     {"t", {pose.translation.x(), pose.translation.y(), pose.translation.z()}}});
  }
  truth["world_from_plane"] = poses;
  ARCO_RETURN_IF_ERROR(WriteJsonFile(JoinPath(tmp, "truth.json"), truth));
  return outputs.Commit();
}

StatusOr<PlaneSceneTruth> ReadPlaneSceneTruth(const std::string& path) {
  ARCO_ASSIGN_OR_RETURN(const Json json, ReadJsonFile(path));
  auto fail = [&](const std::string& what) { return Status::Error(path + ": " + what); };
  if (!json.is_object() || json.value("format", "") != "arco-plane-scene") {
    return fail("not a plane scene truth file (format is not \"arco-plane-scene\")");
  }
  PlaneSceneTruth truth;
  try {
    const Json& texture = json.at("texture");
    truth.texture_width_px = texture.at("width_px").get<int>();
    truth.texture_height_px = texture.at("height_px").get<int>();
    truth.width_mm = texture.at("width_mm").get<double>();
    truth.height_mm = texture.at("height_mm").get<double>();
    truth.fps = media::Rational{json.at("fps").at(0).get<int>(), json.at("fps").at(1).get<int>()};
    truth.calibration = json.at("calibration").get<std::string>();
    for (const Json& video : json.at("videos")) {
      truth.videos.emplace_back(video.at("camera").get<std::string>(),
                                video.at("path").get<std::string>());
    }
    for (const Json& pose : json.at("world_from_plane")) {
      const Json& r = pose.at("R");
      const Json& t = pose.at("t");
      if (r.size() != 9 || t.size() != 3) return fail("world_from_plane needs R[9] and t[3]");
      Eigen::Matrix3d rotation;
      for (int i = 0; i < 9; ++i) rotation(i / 3, i % 3) = r.at(i).get<double>();
      CheckRotationMatrix(rotation, "world_from_plane");
      truth.world_from_plane.emplace_back(
          rotation,
          Eigen::Vector3d(t.at(0).get<double>(), t.at(1).get<double>(), t.at(2).get<double>()));
    }
  } catch (const std::exception& e) {
    return fail(std::string("malformed: ") + e.what());
  }
  if (truth.texture_width_px < 1 || truth.texture_height_px < 1 || !(truth.width_mm > 0) ||
      !(truth.height_mm > 0) || truth.fps.num <= 0 || truth.fps.den <= 0) {
    return fail("texture size and fps must be positive");
  }
  return truth;
}

}  // namespace arco::testing
