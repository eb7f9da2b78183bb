#include "arco/testing/plane_scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>

#include "arco/camera/calibration_io.h"
#include "arco/geometry/triangulation.h"
#include "arco/media/video_reader.h"
#include "arco/media/video_writer.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"

namespace arco::testing {
namespace {

namespace fs = std::filesystem;
using media::Image;
using media::PixelFormat;

constexpr int kDotSpacing = 100;  // texels (= mm: 1 mm per texel)
constexpr double kDotRadius = 12;

// Black anti-aliased dots on white (255) paper, centred on texel centres (so each
// dot is symmetric and its centroid is its centre), 1 mm per texel.
PlaneTexture DotTexture(int width = 700, int height = 500) {
  PlaneTexture texture;
  texture.image = media::MakeImage(width, height, PixelFormat::kGray8);
  texture.width_mm = width;
  texture.height_mm = height;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const double du = std::remainder(u - 50.0, kDotSpacing);
      const double dv = std::remainder(v - 50.0, kDotSpacing);
      double coverage = 0;  // of the texel by the disk, 8x8 samples
      for (int j = 0; j < 8; ++j) {
        for (int i = 0; i < 8; ++i) {
          const double x = du + (i + 0.5) / 8 - 0.5, y = dv + (j + 0.5) / 8 - 0.5;
          coverage += (x * x + y * y <= kDotRadius * kDotRadius) ? 1.0 / 64 : 0.0;
        }
      }
      texture.image.row(v)[u] = static_cast<uint8_t>(std::lround(255 * (1 - coverage)));
    }
  }
  return texture;
}

// Dot centres in texture pixels (at least 50 texels from every edge).
std::vector<Eigen::Vector2d> DotCentres(const PlaneTexture& texture) {
  std::vector<Eigen::Vector2d> centres;
  for (int v = 50; v <= texture.image.height - 50; v += kDotSpacing) {
    for (int u = 50; u <= texture.image.width - 50; u += kDotSpacing) centres.emplace_back(u, v);
  }
  return centres;
}

// Darkness-weighted centroid (255 - value) in a window around `near`; nullopt when the
// window leaves the image.
std::optional<Eigen::Vector2d> DarkCentroid(const Image& image,
                                            const Eigen::Vector2d& near,
                                            int half) {
  const int x0 = static_cast<int>(std::lround(near.x())) - half;
  const int y0 = static_cast<int>(std::lround(near.y())) - half;
  if (x0 < 0 || y0 < 0 || x0 + 2 * half >= image.width || y0 + 2 * half >= image.height) {
    return std::nullopt;
  }
  double sum = 0, sx = 0, sy = 0;
  for (int y = y0; y <= y0 + 2 * half; ++y) {
    for (int x = x0; x <= x0 + 2 * half; ++x) {
      const double w = 255.0 - image.at(x, y);
      sum += w;
      sx += w * x;
      sy += w * y;
    }
  }
  if (sum <= 0) return std::nullopt;
  return Eigen::Vector2d(sx / sum, sy / sum);
}

Rig SmallRig(int cameras = 5, double distortion = 1, uint64_t seed = 3) {
  PlaneRigOptions options;
  options.cameras = cameras;
  options.distortion = distortion;
  options.seed = seed;
  return MakePlaneRig(options);
}

// The window half-size around a dot: the dot's projected radius is ~5 px (12 mm at
// 2.5 m, f ~ 960 px); neighbours are ~30 px away.
constexpr int kHalf = 11;

TEST(ProjectPlanePoint, RenderedDotCentroidsAreAtTheExactProjection) {
  const PlaneTexture texture = DotTexture();
  const Rig rig = SmallRig();
  PlaneMotionOptions motion;
  motion.frames = 40;
  const std::vector<Rigid3d> poses = MakePlaneMotion(motion);
  int checked = 0;
  double worst_px = 0;
  for (const Camera& camera : rig.cameras) {
    const PlaneRenderer renderer(camera);
    const Image background =
        MakeSolidImage(camera.width, camera.height, PixelFormat::kGray8, {255});
    for (int f : {0, 17, 39}) {
      Image view;
      renderer.Render(poses[f], texture, background, &view);
      for (const Eigen::Vector2d& dot : DotCentres(texture)) {
        const auto truth = ProjectPlanePoint(camera, poses[f], texture, dot);
        ASSERT_TRUE(truth.has_value());
        const auto centroid = DarkCentroid(view, *truth, kHalf);
        if (!centroid) continue;  // near the image border
        const double error = (*centroid - *truth).norm();
        worst_px = std::max(worst_px, error);
        EXPECT_LT(error, 0.1) << camera.name << " frame " << f << " dot " << dot.transpose();
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 300) << "too few dots inside the views";
  std::printf("dot centroids: %d checked, worst %.4f px\n", checked, worst_px);
}

TEST(PlaneRenderer, UndistortionIsExactForEverySample) {
  for (const Camera& camera : SmallRig(4, 2.0).cameras) {  // twice the default distortion
    const PlaneRenderer renderer(camera);
    EXPECT_EQ(renderer.invalid_samples(), 0) << camera.name;
    EXPECT_LT(renderer.max_undistortion_error_px(), 1e-8) << camera.name;
  }
}

TEST(PlaneRenderer, DistortedAndPinholeRendersDifferAsTheModelSays) {
  const PlaneTexture texture = DotTexture(1500, 900);  // dots out to the image's edges
  const Camera distorted = SmallRig(1, 2.0, 11).cameras[0];
  Camera pinhole = distorted;
  pinhole.distortion = Distortion();
  const Rigid3d pose = PlaneRestPose();
  const Image background =
      MakeSolidImage(distorted.width, distorted.height, PixelFormat::kGray8, {255});
  const Image view_d = RenderView(distorted, pose, texture, background);
  const Image view_u = RenderView(pinhole, pose, texture, background);
  int checked = 0;
  double largest_shift = 0;
  for (const Eigen::Vector2d& dot : DotCentres(texture)) {
    const auto pinhole_px = ProjectPlanePoint(pinhole, pose, texture, dot);
    ASSERT_TRUE(pinhole_px.has_value());
    const auto c_u = DarkCentroid(view_u, *pinhole_px, kHalf);
    if (!c_u) continue;
    // The model's prediction of where the pinhole image's dot moves with distortion.
    const double y = (c_u->y() - pinhole.cy) / pinhole.fy;
    const double x = (c_u->x() - pinhole.cx - pinhole.skew * y) / pinhole.fx;
    double xd, yd;
    distorted.Distort(x, y, &xd, &yd);
    const Eigen::Vector2d predicted(distorted.fx * xd + distorted.skew * yd + distorted.cx,
                                    distorted.fy * yd + distorted.cy);
    const auto c_d = DarkCentroid(view_d, predicted, kHalf);
    if (!c_d) continue;
    EXPECT_LT((*c_d - predicted).norm(), 0.15) << "dot " << dot.transpose();
    largest_shift = std::max(largest_shift, (*c_d - *c_u).norm());
    ++checked;
  }
  EXPECT_GT(checked, 20);
  EXPECT_GT(largest_shift, 2.0) << "the distortion should move the outer dots by pixels";
}

TEST(ProjectPlanePoint, BehindTheCameraOutsideTheViewAndBeyondTheLens) {
  const PlaneTexture texture = DotTexture(200, 100);
  Camera camera = SmallRig(1, 1.0).cameras[0];
  // The plane behind the camera: nothing projects, the render is the background.
  const Rigid3d camera_in_world(Eigen::Quaterniond(camera.cam_from_world.rotation.transpose()),
                                camera.CenterInWorld());
  const Rigid3d behind =
      camera_in_world * Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, -500));
  EXPECT_FALSE(ProjectPlanePoint(camera, behind, texture, {100, 50}).has_value());
  const Image background =
      MakeSolidImage(camera.width, camera.height, PixelFormat::kRgb8, {1, 2, 3});
  EXPECT_TRUE(RenderView(camera, behind, texture, background).pixels == background.pixels);

  // In front, facing the camera, 500 mm ahead: the centre projects into the image.
  const Rigid3d ahead =
      camera_in_world * Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 500));
  const auto centre = ProjectPlanePoint(camera, ahead, texture, {99.5, 49.5});
  ASSERT_TRUE(centre.has_value());
  EXPECT_TRUE(InImage(camera, *centre));
  // Sideways by 5 plane widths: still in front, outside the image.
  const Rigid3d aside =
      camera_in_world * Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1000, 0, 500));
  const auto outside = ProjectPlanePoint(camera, aside, texture, {99.5, 49.5});
  ASSERT_TRUE(outside.has_value());
  EXPECT_FALSE(InImage(camera, *outside));

  // A plane through the camera's centre plane: the near half behind, the far half in front.
  const Rigid3d tilted =
      camera_in_world *
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(1.2, Eigen::Vector3d::UnitY())),
              Eigen::Vector3d(0, 0, 10));
  const auto left = ProjectPlanePoint(camera, tilted, texture, {0, 50});
  const auto right = ProjectPlanePoint(camera, tilted, texture, {199, 50});
  EXPECT_NE(left.has_value(), right.has_value());

  // A lens whose radial model folds at r = 1 / sqrt(0.9): points beyond are not seen.
  camera.distortion = Distortion();
  camera.distortion.k1 = -0.3;
  EXPECT_NEAR(InvertibleRadius(camera.distortion), 1 / std::sqrt(0.9), 1e-9);
  EXPECT_TRUE(std::isinf(InvertibleRadius(Distortion())));
  const Rigid3d far_aside = camera_in_world * Rigid3d(Eigen::Quaterniond::Identity(),
                                                      Eigen::Vector3d(600, 0, 500));  // r = 1.2
  EXPECT_FALSE(ProjectPlanePoint(camera, far_aside, texture, {99.5, 49.5}).has_value());
}

TEST(PlaneRenderer, OneSidedPlaneShowsBackgroundFromBehind) {
  const PlaneTexture texture = DotTexture();
  const Camera camera = SmallRig(1).cameras[0];
  const Image background = MakeSolidImage(camera.width, camera.height, PixelFormat::kGray8, {7});
  PlaneRenderOptions one_sided;
  one_sided.two_sided = false;
  const Rigid3d front = PlaneRestPose();
  const Rigid3d back(
      front.rotation * Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY())),
      front.translation);
  EXPECT_FALSE(RenderView(camera, front, texture, background, one_sided).pixels ==
               background.pixels);
  EXPECT_TRUE(RenderView(camera, back, texture, background, one_sided).pixels == background.pixels);
  EXPECT_FALSE(RenderView(camera, back, texture, background).pixels == background.pixels);
}

TEST(PlaneRenderer, ThreadsDoNotChangeTheImageAndBadInputThrows) {
  const PlaneTexture texture = DotTexture();
  const Camera camera = SmallRig(1).cameras[0];
  const Image background =
      MakeSolidImage(camera.width, camera.height, PixelFormat::kRgb8, {9, 99, 199});
  PlaneRenderOptions threaded;
  threaded.threads = 3;
  const Rigid3d pose = MakePlaneMotion({})[5];
  EXPECT_TRUE(RenderView(camera, pose, texture, background).pixels ==
              RenderView(camera, pose, texture, background, threaded).pixels);

  PlaneRenderOptions bad;
  bad.supersampling = 0;
  EXPECT_FALSE(bad.Validate().ok());
  EXPECT_THROW(PlaneRenderer(camera, bad), std::invalid_argument);
  const Image small = MakeSolidImage(10, 10, PixelFormat::kRgb8, {0, 0, 0});
  EXPECT_THROW(RenderView(camera, pose, texture, small), std::invalid_argument);
  PlaneTexture no_size = texture;
  no_size.width_mm = 0;
  EXPECT_THROW(RenderView(camera, pose, no_size, background), std::invalid_argument);
}

// One-texel black/white stripes shrunk about 5x: without the pyramid the samples
// alias into strong moire; with it the plane is an even gray.
TEST(PlaneRenderer, MipmapsRemoveAliasingOfFineTextures) {
  PlaneTexture stripes;
  stripes.image = media::MakeImage(2000, 1400, PixelFormat::kGray8);
  for (int v = 0; v < 1400; ++v) {
    for (int u = 0; u < 2000; ++u) stripes.image.row(v)[u] = (u % 2 == 0) ? 0 : 255;
  }
  stripes.width_mm = 1000;
  stripes.height_mm = 700;
  const Camera camera = SmallRig(1).cameras[0];
  const Image background = MakeSolidImage(camera.width, camera.height, PixelFormat::kGray8, {0});
  // Spread of the plane's pixels in the middle of the view, where the plane surely is.
  auto spread = [&](const Image& view) {
    double sum = 0, sum2 = 0;
    int n = 0;
    for (int y = camera.height / 2 - 60; y < camera.height / 2 + 60; ++y) {
      for (int x = camera.width / 2 - 100; x < camera.width / 2 + 100; ++x) {
        sum += view.at(x, y);
        sum2 += double(view.at(x, y)) * view.at(x, y);
        ++n;
      }
    }
    const double mean = sum / n;
    EXPECT_NEAR(mean, 127.5, 12);
    return std::sqrt(std::max(0.0, sum2 / n - mean * mean));
  };
  PlaneRenderOptions plain;
  plain.mipmap = false;
  const double with_mipmaps = spread(RenderView(camera, PlaneRestPose(), stripes, background));
  const double without = spread(RenderView(camera, PlaneRestPose(), stripes, background, plain));
  EXPECT_LT(with_mipmaps, 6.0);
  EXPECT_GT(without, 4 * with_mipmaps);
  std::printf("stripes: spread %.2f with mipmaps, %.2f without\n", with_mipmaps, without);

  BuildMipmaps(&stripes);
  EXPECT_EQ(stripes.mipmaps[0].width, 1000);
  EXPECT_EQ(stripes.mipmaps.back().width, 1);
  EXPECT_EQ(stripes.mipmaps.back().height, 1);
  stripes.image = media::MakeImage(30, 30, PixelFormat::kGray8);  // stale mipmaps
  EXPECT_THROW(stripes.Check(), std::invalid_argument);
}

TEST(MakePlaneMotion, SmoothSeededAndWithinItsBounds) {
  PlaneMotionOptions options;
  options.frames = 300;
  const std::vector<Rigid3d> poses = MakePlaneMotion(options);
  ASSERT_EQ(poses.size(), 300u);
  const Rigid3d rest = PlaneRestPose();
  double max_t = 0, max_angle = 0;
  for (size_t f = 0; f < poses.size(); ++f) {
    max_t = std::max(max_t, (poses[f].translation - rest.translation).cwiseAbs().maxCoeff());
    const Eigen::Quaterniond motion = poses[f].rotation * rest.rotation.inverse();
    max_angle = std::max(max_angle, Eigen::AngleAxisd(motion).angle() * 180 / M_PI);
    if (f > 0) {  // < 0.7 Hz * 2 pi * 150 mm / 30 fps per axis
      EXPECT_LT((poses[f].translation - poses[f - 1].translation).norm(), 40.0);
    }
  }
  EXPECT_LE(max_t, 150.0 + 1e-9);
  EXPECT_GT(max_t, 50.0) << "the plane should move";
  EXPECT_LE(max_angle, 15.0 * std::sqrt(3.0) + 1e-9);
  EXPECT_GT(max_angle, 5.0);
  EXPECT_TRUE(MakePlaneMotion(options)[77].translation == poses[77].translation);
  options.seed = 2;
  EXPECT_FALSE(MakePlaneMotion(options)[77].translation == poses[77].translation);
  options.frames = 0;
  EXPECT_THROW(MakePlaneMotion(options), std::invalid_argument);
}

TEST(MakePlaneRig, CamerasSeeThePlaneAndCarryDistortion) {
  const Rig rig = SmallRig(7);
  ASSERT_EQ(rig.cameras.size(), 7u);
  EXPECT_EQ(rig.units, "mm");
  EXPECT_TRUE(ValidateRig(rig).ok());
  const PlaneTexture texture = DotTexture();
  for (const Camera& camera : rig.cameras) {
    const double distance = camera.CenterInWorld().norm();
    EXPECT_GT(distance, 2000);
    EXPECT_LT(distance, 3000);
    EXPECT_FALSE(camera.distortion.IsZero());
    const auto centre = ProjectPlanePoint(camera, PlaneRestPose(), texture, {349.5, 249.5});
    ASSERT_TRUE(centre.has_value());
    EXPECT_TRUE(InImage(camera, *centre)) << camera.name;
  }
  PlaneRigOptions bad;
  bad.cameras = 0;
  EXPECT_THROW(MakePlaneRig(bad), std::invalid_argument);
}

class PlaneSceneFolder : public ::testing::Test {
 protected:
  TempDir temp_;
  const fs::path dir_{temp_.path()};
};

TEST_F(PlaneSceneFolder, WritesVideosCalibrationAndTruthThatReadBack) {
  PlaneScene scene;
  PlaneRigOptions rig;
  rig.cameras = 3;
  rig.width = 320;
  rig.height = 180;
  rig.focal_px = 330;
  scene.rig = MakePlaneRig(rig);
  scene.texture = DotTexture();
  PlaneMotionOptions motion;
  motion.frames = 6;
  scene.world_from_plane = MakePlaneMotion(motion);
  scene.fps = {30, 1};
  for (int c = 0; c < 3; ++c) {  // static backgrounds: a gradient per camera
    Image background = media::MakeImage(320, 180, PixelFormat::kRgb8);
    for (int y = 0; y < 180; ++y) {
      for (int x = 0; x < 320; ++x) {
        uint8_t* p = background.row(y) + 3 * x;
        p[0] = static_cast<uint8_t>(x * 255 / 319);
        p[1] = static_cast<uint8_t>(y * 255 / 179);
        p[2] = static_cast<uint8_t>(80 * c);
      }
    }
    scene.backgrounds.push_back(background);
  }
  const std::string folder = (dir_ / "scene").string();
  const Status written = WritePlaneScene(scene, folder);
  ASSERT_TRUE(written.ok()) << written.message();

  auto truth = ReadPlaneSceneTruth(folder + "/truth.json");
  ASSERT_TRUE(truth.ok()) << truth.status().message();
  EXPECT_EQ(truth->texture_width_px, 700);
  EXPECT_EQ(truth->height_mm, 500);
  EXPECT_EQ(truth->fps.num, 30);
  ASSERT_EQ(truth->world_from_plane.size(), 6u);
  for (size_t f = 0; f < 6; ++f) {
    EXPECT_LT((truth->world_from_plane[f].ToMatrix() - scene.world_from_plane[f].ToMatrix())
                  .cwiseAbs()
                  .maxCoeff(),
              1e-12);
  }
  auto text = ReadFileToString(folder + "/" + truth->calibration);
  ASSERT_TRUE(text.ok());
  auto calibration = ParseArcoJson(*text, "calibration.json");
  ASSERT_TRUE(calibration.ok()) << calibration.status().message();
  ASSERT_EQ(calibration->rig.cameras.size(), 3u);
  ASSERT_EQ(truth->videos.size(), 3u);
  for (size_t c = 0; c < 3; ++c) {
    const Camera& camera = calibration->rig.cameras[c];
    EXPECT_EQ(truth->videos[c].first, camera.name);
    EXPECT_NEAR(camera.distortion.k1, scene.rig.cameras[c].distortion.k1, 1e-12);
    auto reader = media::VideoReader::Open(folder + "/" + truth->videos[c].second);
    ASSERT_TRUE(reader.ok()) << reader.status().message();
    EXPECT_EQ(reader->properties().frame_count, 6);
    EXPECT_EQ(reader->properties().width, 320);
    EXPECT_EQ(reader->properties().height, 180);
    EXPECT_EQ(reader->properties().fps.num, 30);
    // Lossless: frame 4 is the render, bit for bit.
    auto frame = reader->ReadFrame(4);
    ASSERT_TRUE(frame.ok()) << frame.status().message();
    const Image expected = RenderView(
        scene.rig.cameras[c], scene.world_from_plane[4], scene.texture, scene.backgrounds[c]);
    EXPECT_TRUE(frame->pixels == expected.pixels) << camera.name;
  }

  // The files alone are consistent: texture points projected with the stored cameras
  // and poses triangulate back onto their place on the plane.
  std::vector<Eigen::Vector3d> centers;
  for (const Camera& camera : calibration->rig.cameras) centers.push_back(camera.CenterInWorld());
  const WorldConditioning conditioning = ConditioningFromCameraCenters(centers);
  PlaneTexture stored;
  stored.image =
      media::MakeImage(truth->texture_width_px, truth->texture_height_px, PixelFormat::kGray8);
  stored.width_mm = truth->width_mm;
  stored.height_mm = truth->height_mm;
  for (size_t f = 0; f < truth->world_from_plane.size(); ++f) {
    for (const Eigen::Vector2d& texture_px :
         {Eigen::Vector2d(0, 0), Eigen::Vector2d(350, 250), Eigen::Vector2d(699, 120)}) {
      std::vector<DltObservation> observations;
      for (const Camera& camera : calibration->rig.cameras) {
        const auto pixel =
            ProjectPlanePoint(camera, truth->world_from_plane[f], stored, texture_px);
        ASSERT_TRUE(pixel.has_value());
        observations.push_back({camera.ProjectionMatrix(), camera.UndistortPixel(*pixel), 1.0});
      }
      const auto point = TriangulateDlt(observations, conditioning);
      ASSERT_TRUE(point.has_value());
      const Eigen::Vector3d expected =
          PlaneToWorld(scene.world_from_plane[f], TexturePixelToPlane(scene.texture, texture_px));
      EXPECT_LT((*point - expected).norm(), 1e-6) << "frame " << f;
    }
  }

  // An existing scene is replaced only with overwrite; bad scenes write nothing.
  EXPECT_FALSE(WritePlaneScene(scene, folder).ok());
  PlaneSceneWriteOptions overwrite;
  overwrite.overwrite = true;
  EXPECT_TRUE(WritePlaneScene(scene, folder, overwrite).ok());
  PlaneScene wrong_background = scene;
  wrong_background.backgrounds.assign(3, MakeSolidImage(32, 18, PixelFormat::kRgb8, {0, 0, 0}));
  const Status bad_background = WritePlaneScene(wrong_background, (dir_ / "bg").string());
  ASSERT_FALSE(bad_background.ok());
  EXPECT_NE(bad_background.message().find("background of camera cam0"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir_ / "bg"));
  PlaneScene empty = scene;
  empty.world_from_plane.clear();
  const Status no_frames = WritePlaneScene(empty, (dir_ / "empty").string());
  EXPECT_FALSE(no_frames.ok());
  EXPECT_FALSE(fs::exists(dir_ / "empty"));
}

TEST_F(PlaneSceneFolder, TruthReaderRejectsMalformedFiles) {
  const std::string path = (dir_ / "truth.json").string();
  for (const char* text : {"{}",
                           "[1, 2]",
                           R"({"format": "arco-plane-scene"})",
                           R"({"format": "arco-plane-scene", "texture": {"width_px": 4,
                              "height_px": 4, "width_mm": 1, "height_mm": 1}, "fps": [30, 1],
                              "calibration": "c.json", "videos": [],
                              "world_from_plane": [{"R": [1, 0, 0, 0, 1, 0, 0, 0, 2],
                              "t": [0, 0, 0]}]})"}) {
    ASSERT_TRUE(AtomicWriteFile(path, text).ok());
    const auto truth = ReadPlaneSceneTruth(path);
    ASSERT_FALSE(truth.ok()) << text;
    EXPECT_EQ(truth.status().message().rfind(path + ": ", 0), 0u) << truth.status().message();
  }
  EXPECT_FALSE(ReadPlaneSceneTruth((dir_ / "missing.json").string()).ok());
}

// A real photo (a cellist) on a 1.0 x 1.15 m plane in two views. Set
// ARCO_PLANE_SMOKE_DIR to keep the PNGs for a look.
TEST(RenderView, RealPhotoSmokeRender) {
  auto reader = media::VideoReader::Open(std::string(ARCO_SHARED_DATA_DIR) + "/spd/example.jpg");
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  auto photo = reader->ReadFrame(0);
  ASSERT_TRUE(photo.ok()) << photo.status().message();
  PlaneTexture texture;
  texture.image = *photo;
  texture.height_mm = 1150;
  texture.width_mm = 1150.0 * photo->width / photo->height;
  PlaneRigOptions rig_options;
  rig_options.cameras = 2;
  rig_options.arc_deg = 60;
  const Rig rig = MakePlaneRig(rig_options);
  const Rigid3d pose = MakePlaneMotion({})[10];
  const char* keep = std::getenv("ARCO_PLANE_SMOKE_DIR");
  for (const Camera& camera : rig.cameras) {
    const Image background =
        MakeSolidImage(camera.width, camera.height, PixelFormat::kRgb8, {0, 90, 0});
    const Image view = RenderView(camera, pose, texture, background);
    int64_t plane_pixels = 0;
    for (int y = 0; y < view.height; ++y) {
      for (int x = 0; x < view.width; ++x) {
        plane_pixels += view.at(x, y, 0) != 0 || view.at(x, y, 1) != 90 || view.at(x, y, 2) != 0;
      }
    }
    EXPECT_GT(plane_pixels, int64_t(view.width) * view.height / 4) << camera.name;
    EXPECT_LT(plane_pixels, int64_t(view.width) * view.height * 9 / 10) << camera.name;
    // The photo's centre is in view.
    const Eigen::Vector2d centre_px(photo->width / 2, photo->height / 2);
    const auto where = ProjectPlanePoint(camera, pose, texture, centre_px);
    ASSERT_TRUE(where && InImage(camera, *where));
    if (keep != nullptr) {
      const Status saved =
          media::WriteImageFile(std::string(keep) + "/plane_" + camera.name + ".png", view);
      EXPECT_TRUE(saved.ok()) << saved.message();
    }
  }
}

}  // namespace
}  // namespace arco::testing
