// Moving-plane scenes: a photo on a flat rectangle that moves rigidly in front of
// calibrated cameras with lens distortion, rendered by exact inverse warping. A test
// fixture with exact truth for detection and tracking from video: every texture point's
// pixel in every view and frame is known (ProjectPlanePoint), and a flat picture's
// points must triangulate onto the plane and stay still on it.
//
// Conventions (stated once here):
// - Texture pixels: (u, v) = (column, row) with the origin at the CENTRE of the top-left
//   pixel (as camera.h's image pixels); the image covers [-0.5, W - 0.5] x [-0.5, H - 0.5].
// - Plane frame, mm: origin at the texture's centre, x along the texture's rows (to
//   the right), y down its columns, z = x cross y. The texture maps linearly onto the
//   rectangle [-width_mm/2, width_mm/2] x [-height_mm/2, height_mm/2] at z = 0. A camera
//   on the plane's -z side sees the picture the right way round (from +z, mirrored).
// - world_from_plane maps plane points to world points (transform.h); world units mm.
//
// Rendering (PlaneRenderer): for every output sample, the camera model's own
// undistortion (Camera::PixelToNormalized, Gauss-Newton on the forward model) gives
// the ray's normalised coordinates, precomputed once per camera; each is checked by
// distorting it back (max_undistortion_error_px) and samples outside the region where
// the radial model is invertible are background. Per frame the ray meets the plane
// through the exact homography between the normalised image plane and the plane
// (H = [r1 r2 t] of cam_from_plane), the hit is mapped to texture pixels and sampled
// bilinearly (edge pixels clamped; outside the rectangle: background). Anti-aliasing:
// `supersampling` x `supersampling` samples per pixel on a regular grid, averaged (a box
// filter over the pixel's area, as a sensor integrates); 1 renders the pixel centres.
// A photo shrunk several times (a 2300 px photo into a 400 px wide view) would still
// alias, so with `mipmap` each sample reads a box-filtered pyramid of the texture
// (trilinear: the two levels around log2(texels per sample), from the homography's
// Jacobian), as GPUs do. Texels are never finer than a sample, at the cost of some
// blur where the plane is seen obliquely (the larger axis picks the level).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "arco/camera/camera.h"
#include "arco/camera/rig.h"
#include "arco/geometry/transform.h"
#include "arco/media/image.h"
#include "arco/media/video_reader.h"
#include "arco/util/progress.h"
#include "arco/util/status.h"

namespace arco::testing {

// A picture on a flat rectangle of a physical size.
struct PlaneTexture {
  media::Image image;  // RGB8 or Gray8
  double width_mm = 0, height_mm = 0;
  // Levels 1, 2, ... of the box-filtered pyramid of `image` (level k's texel covers
  // 2^k x 2^k pixels), for anti-aliased minification: filled by BuildMipmaps; empty,
  // PlaneRenderer::Render builds them on every call.
  std::vector<media::Image> mipmaps;
  // Throws std::invalid_argument on an empty image, a non-positive size or mipmaps of
  // another image's size.
  void Check() const;
};
// Fills texture->mipmaps from texture->image (call again after changing the image).
void BuildMipmaps(PlaneTexture* texture);

// Texture pixel -> plane point (mm, z = 0) and back; linear.
Eigen::Vector2d TexturePixelToPlane(const PlaneTexture& texture, const Eigen::Vector2d& texture_px);
Eigen::Vector2d PlaneToTexturePixel(const PlaneTexture& texture,
                                    const Eigen::Vector2d& point_in_plane);
Eigen::Vector3d PlaneToWorld(const Rigid3d& world_from_plane,
                             const Eigen::Vector2d& point_in_plane);

// Largest normalised radius below which the camera's radial distortion is invertible
// (r (1 + k1 r^2 + k2 r^4 + k3 r^6) increasing); +infinity when it never folds.
double InvertibleRadius(const Distortion& distortion);

// The exact pixel where texture point `texture_px` appears in `camera` (with
// distortion); nullopt when it is behind the camera or outside the lens model's
// invertible region (no pixel sees it). The pixel may lie outside the image: see
// InImage.
std::optional<Eigen::Vector2d> ProjectPlanePoint(const Camera& camera,
                                                 const Rigid3d& world_from_plane,
                                                 const PlaneTexture& texture,
                                                 const Eigen::Vector2d& texture_px);
// Whether a pixel lies on the image: [-0.5, width - 0.5) x [-0.5, height - 0.5).
bool InImage(const Camera& camera, const Eigen::Vector2d& pixel);

struct PlaneRenderOptions {
  int supersampling = 2;  // samples per pixel side (1..8)
  bool mipmap = true;     // sample a texture pyramid where texels are finer than samples
  // Undistortion is checked per sample by distorting back: a larger round-trip error
  // marks the sample invalid (background) and counts it (invalid_samples()).
  double max_undistortion_error_px = 1e-6;
  bool two_sided = true;  // false: the plane's back (+z side) shows background
  int threads = 1;        // rows rendered in parallel (deterministic for any count)
  Status Validate() const;
};

// Renders one camera's views of a plane; the rays are computed once (allocate at
// configuration), each Render is a homography, a bilinear sample and an average.
class PlaneRenderer {
 public:
  // Throws std::invalid_argument on invalid options or a camera without a size.
  explicit PlaneRenderer(const Camera& camera, const PlaneRenderOptions& options = {});

  // Renders into *out: `background` (the camera's size; its format is the output's)
  // where no plane is seen. Throws std::invalid_argument on a background of the wrong
  // size or an invalid texture. Gray textures are replicated into RGB, RGB textures
  // reduced to luma (BT.601) for gray output.
  void Render(const Rigid3d& world_from_plane,
              const PlaneTexture& texture,
              const media::Image& background,
              media::Image* out) const;

  const Camera& camera() const { return camera_; }
  // Samples whose undistortion failed the round-trip check or lie outside the
  // invertible region: 0 for ordinary lenses.
  int64_t invalid_samples() const { return invalid_samples_; }
  // The largest undistortion round-trip error over valid samples, px.
  double max_undistortion_error_px() const { return max_error_px_; }

 private:
  Camera camera_;
  PlaneRenderOptions options_;
  // Normalised (x, y) of every sample, row-major by sample row; NaN when invalid.
  std::vector<Eigen::Vector2d> rays_;
  int64_t invalid_samples_ = 0;
  double max_error_px_ = 0;
};

// One view, with a renderer built for it.
media::Image RenderView(const Camera& camera,
                        const Rigid3d& world_from_plane,
                        const PlaneTexture& texture,
                        const media::Image& background,
                        const PlaneRenderOptions& options = {});

// An image filled with one colour (gray: the first component).
media::Image MakeSolidImage(int width,
                            int height,
                            media::PixelFormat format,
                            std::array<uint8_t, 3> rgb);

// A rig of cameras on an arc around the plane, at about SPD's scale (world: mm, z up;
// the plane's rest pose faces the cameras, see PlaneRestPose).
struct PlaneRigOptions {
  int cameras = 7;
  int width = 960, height = 540;  // px (1920x1080 for full size)
  double focal_px = 0;            // 0: the image width (about 53 deg horizontal FOV)
  double distance_mm = 2500;      // camera centre to the point it looks at
  double arc_deg = 100;           // cameras spread evenly over this arc around world z
  double height_mm = 300;         // camera heights alternate above and below the centre
  // Scale of the random lens distortion: 1 gives k1 in [-0.09, 0.03], k2 in
  // [-0.02, 0.08], k3 in [-0.01, 0.01], p1, p2 in [-0.002, 0.002] (a few px at the
  // corners of a 960 px image); 0: no distortion.
  double distortion = 1;
  uint64_t seed = 1;
  Status Validate() const;
};
// Cameras "cam0".."camN-1", units "mm"; also jitters focal length, principal point,
// aim and roll a little (seeded). Throws std::invalid_argument on invalid options.
Rig MakePlaneRig(const PlaneRigOptions& options);

// The plane at the world origin, upright, facing the cameras (-y): plane x = world x,
// plane y = world -z.
Rigid3d PlaneRestPose();

struct PlaneMotionOptions {
  int frames = 60;
  double fps_hz = 30;
  double max_translation_mm = 150;  // per world axis
  double max_rotation_deg = 15;     // per world axis, about the plane's centre
  uint64_t seed = 1;
  Status Validate() const;
};
// world_from_plane per frame: the rest pose moved smoothly (every component a sum of
// three seeded sinusoids of 0.1..0.7 Hz whose amplitudes add up to the maximum).
// Throws std::invalid_argument on invalid options.
std::vector<Rigid3d> MakePlaneMotion(const PlaneMotionOptions& options);

struct PlaneScene {
  Rig rig;  // units mm
  PlaneTexture texture;
  std::vector<Rigid3d> world_from_plane;  // one per frame
  media::Rational fps{30, 1};
  std::array<uint8_t, 3> background_rgb{90, 90, 90};
  // Optional static backgrounds, one per camera (RGB8, the camera's size), e.g. a room
  // for a tracker to ignore; empty: background_rgb everywhere.
  std::vector<media::Image> backgrounds;
};

// The detection plane test's scene (capture/detect_plane_test.cc, bench/detect_bench.cc
// BM_DetectStagePlane): `photo` (SPD's example.jpg) at 0.778 mm per pixel (its
// nut-to-bridge distance, about 895 px, is a cello's 695 mm string), 8 cameras of
// 1152 x 1328 px (half SPD's portrait frame, focal 1130 px) on a 100 degree arc at 2.5 m,
// 12 frames at 30 fps moving up to 150 mm and 10 degrees per axis.
PlaneScene DetectPlaneScene(const media::Image& photo);

struct PlaneSceneWriteOptions {
  PlaneRenderOptions render;
  std::string container = "matroska";  // with the extension below
  std::string codec = "ffv1";          // lossless
  std::string extension = ".mkv";
  bool overwrite = false;  // replace an existing scene folder (one holding truth.json)
  // Cameras rendered and encoded in parallel (0 = all cores); each camera's video is
  // the same for any count. render.threads splits each camera's rows on top.
  int threads = 0;
};

// Writes a scene folder atomically (util/output_set.h):
//   FOLDER/calibration.json   arco JSON (SaveCalibration's format), mm
//   FOLDER/videos/CAMERA.mkv  one video per camera, every frame rendered
//   FOLDER/truth.json         format "arco-plane-scene": texture size (px, mm), fps,
//                             cameras and their videos, world_from_plane per frame (R
//                             row-major, t in mm), the plane frame's convention
// Progress: one stage, SetTotal(cameras x frames).
Status WritePlaneScene(const PlaneScene& scene,
                       const std::string& folder,
                       const PlaneSceneWriteOptions& options = {},
                       Progress& progress = NoProgress());

// truth.json, read back (the one reader of the writer above).
struct PlaneSceneTruth {
  int texture_width_px = 0, texture_height_px = 0;
  double width_mm = 0, height_mm = 0;
  media::Rational fps;
  std::string calibration;                                  // relative to the folder
  std::vector<std::pair<std::string, std::string>> videos;  // camera, relative path
  std::vector<Rigid3d> world_from_plane;
};
StatusOr<PlaneSceneTruth> ReadPlaneSceneTruth(const std::string& path);

}  // namespace arco::testing
