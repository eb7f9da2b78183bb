// From videos to 3D on real image content with exact geometry (issue 12's multi-view
// test): the real photo of a cellist (../shared/data/spd/example.jpg) on a flat
// rectangle of its physical size moves rigidly in front of 8 calibrated cameras with
// lens distortion (testing/plane_scene.h renders each view by exact inverse warping into
// FFV1 videos). `capture new` -> `detect` -> `triangulate`: because the picture is flat,
// every keypoint the detector finds must triangulate onto the plane and stay still on
// it (in plane coordinates) while the plane moves. Figures are printed for
// docs/accuracy.md; the bounds are issue 12's (median 12 mm off the plane, 6 mm of
// movement on it) and issue 28's (the bowing hand within 30 mm of the plane at the 90th
// percentile, with the hands checked across views: capture/hand_consistency.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "arco/capture/capture_new.h"
#include "arco/capture/detect_stage.h"
#include "arco/detect/models_for_test.h"
#include "arco/media/video_reader.h"
#include "arco/pipeline/triangulate_stage.h"
#include "arco/registry/keypoint_layout.h"
#include "arco/testing/plane_scene.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/npy.h"
#include "arco/util/stats.h"

namespace arco::capture {
namespace {

namespace fs = std::filesystem;

TEST(DetectPlane, KeypointsTriangulateOntoTheMovingPlaneAndStayOnIt) {
  ARCO_REQUIRE_MODELS();
  const std::string photo = std::string(ARCO_SHARED_DATA_DIR) + "/spd/example.jpg";
  ASSERT_TRUE(fs::exists(photo)) << photo;
  testing::TempDir dir;

  // The scene: 8 cameras (half SPD's portrait frame) on a 100 degree arc at 2.5 m.
  auto reader = media::VideoReader::Open(photo);
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  auto image = reader->ReadFrame(0);
  ASSERT_TRUE(image.ok());
  const testing::PlaneScene scene = testing::DetectPlaneScene(*image);
  const int frames = static_cast<int>(scene.world_from_plane.size());
  const std::string scene_dir = dir / "scene";
  const auto start = std::chrono::steady_clock::now();
  const auto seconds = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  testing::PlaneSceneWriteOptions write;
  write.render.supersampling = 1;  // the texture pyramid still filters the shrunk photo
  ASSERT_TRUE(testing::WritePlaneScene(scene, scene_dir, write).ok());
  const double render_s = seconds();

  // capture new -> detect -> triangulate.
  CaptureNewOptions c;
  c.calibration = scene_dir + "/calibration.json";
  for (const Camera& cam : scene.rig.cameras) {
    c.inputs.push_back({cam.name, scene_dir + "/videos/" + cam.name + ".mkv", false});
  }
  c.output_dir = dir / "capture";
  auto made = CreateCapture(c);
  ASSERT_TRUE(made.ok()) << made.status().message();
  DetectStageOptions d;
  d.capture_dir = c.output_dir;
  d.hands.rerun = true;  // the re-run path too (the default down-weights at once)
  // ARCO_PLANE_LITE_HANDS=1: the lite hand model (`arco detect --hand-model lite`), for its
  // figures (docs/performance.md, "Issue 28, part 1, second step"); the bounds still hold.
  if (std::getenv("ARCO_PLANE_LITE_HANDS") != nullptr) {
    d.detector.hand_model = detect::HandModel::kLite;
  }
  auto detected = RunDetectStage(d);
  ASSERT_TRUE(detected.ok()) << detected.status().message();
  const double detect_s = seconds() - render_s;
  const detect::WholeBodySummary& total = detected->total;
  std::printf(
      "rendered %d views x %d frames in %.1f s, detected in %.1f s (per view-frame: "
      "inference %.1f ms, preprocessing %.1f ms, postprocessing %.1f ms, decoding %.1f ms)\n",
      static_cast<int>(scene.rig.cameras.size()),
      frames,
      render_s,
      detect_s,
      1e3 * total.inference_s / total.frames,
      1e3 * total.preprocess_s / total.frames,
      1e3 * total.postprocess_s / total.frames,
      1e3 * detected->decode_s / total.frames);
  std::printf(
      "hand crops from the previous frame's hand: %lld; hands re-used: %lld; "
      "hand_recrop runs: %lld; hand landmarker runs: %lld\n",
      static_cast<long long>(total.hands_tracked),
      static_cast<long long>(total.hands_reused),
      static_cast<long long>(total.models[2].runs),
      static_cast<long long>(total.models[3].runs));
  const HandConsistencySummary& hands = detected->hands;
  std::printf(
      "hands across views: %lld hands judged, %lld views swapped, %lld disagreeing, %lld "
      "re-run (%lld then agreed), %lld down-weighted whole, %lld points down-weighted; "
      "%.2f s (%.1f ms per view-frame)\n",
      static_cast<long long>(hands.hands_judged),
      static_cast<long long>(hands.swapped),
      static_cast<long long>(hands.disagreeing),
      static_cast<long long>(hands.recropped),
      static_cast<long long>(hands.fixed),
      static_cast<long long>(hands.hands_down_weighted),
      static_cast<long long>(hands.points_down_weighted),
      hands.wall_s,
      1e3 * hands.wall_s / total.frames);
  EXPECT_TRUE(hands.ran) << hands.skipped;
  EXPECT_GT(hands.disagreeing, 0);
  EXPECT_EQ(hands.recropped, hands.disagreeing);
  EXPECT_EQ(hands.fixed + hands.hands_down_weighted, hands.recropped);
  for (const auto& cam : detected->cameras) {
    EXPECT_EQ(cam.tracker.frames_with_person, frames) << cam.camera;
  }
  pipeline::TriangulateStageOptions t;
  t.capture_dir = c.output_dir;
  t.result_dir = dir / "result";
  auto triangulated = pipeline::RunTriangulateStage(t);
  ASSERT_TRUE(triangulated.ok()) << triangulated.status().message();
  auto points = ReadNpy<double>(t.result_dir + "/triangulation/points3d_raw.npy");
  ASSERT_TRUE(points.ok()) << points.status().message();
  ASSERT_EQ(points->shape[0], frames);
  const int64_t num_points = points->shape[1];

  // Every triangulated body and hand point in plane coordinates.
  std::vector<double> off_plane_mm;
  // The same by part: the body (with the feet), the left hand, the right (bowing) hand.
  std::array<std::vector<double>, 3> part_off_plane_mm;
  std::vector<double> body_moves_mm, hand_moves_mm;
  int hand_points_seen = 0;
  for (int64_t p = 0; p < std::min<int64_t>(num_points, wholebody::kNumPoints); ++p) {
    std::vector<Eigen::Vector2d> on_plane;
    for (int64_t f = 0; f < frames; ++f) {
      const double* x = &points->data[static_cast<size_t>((f * num_points + p) * 3)];
      if (!std::isfinite(x[0])) continue;
      const Eigen::Vector3d in_plane =
          scene.world_from_plane[f].Inverse() * Eigen::Vector3d(x[0], x[1], x[2]);
      off_plane_mm.push_back(std::abs(in_plane.z()));
      const int part = p < wholebody::kLeftHandFirst ? 0 : p < wholebody::kRightHandFirst ? 1 : 2;
      part_off_plane_mm[part].push_back(std::abs(in_plane.z()));
      on_plane.push_back(in_plane.head<2>());
    }
    if (on_plane.size() < static_cast<size_t>(frames) / 2) continue;
    // Median distance from the point's median position on the plane.
    std::vector<double> xs, ys;
    for (const auto& q : on_plane) {
      xs.push_back(q.x());
      ys.push_back(q.y());
    }
    const Eigen::Vector2d centre(Median(xs), Median(ys));
    std::vector<double> dist;
    for (const auto& q : on_plane) dist.push_back((q - centre).norm());
    const bool hand = p >= wholebody::kLeftHandFirst;
    (hand ? hand_moves_mm : body_moves_mm).push_back(Median(dist));
    if (hand) ++hand_points_seen;
  }
  ASSERT_FALSE(off_plane_mm.empty());
  std::vector<double> all_moves = body_moves_mm;
  all_moves.insert(all_moves.end(), hand_moves_mm.begin(), hand_moves_mm.end());
  const double off_median = Median(off_plane_mm);
  const double move_median = Median(all_moves);
  std::printf(
      "plane test: %zu body + %zu hand keypoints; off the plane median %.1f mm (95th %.1f); "
      "movement on it median %.1f mm (body %.1f, hands %.1f)\n",
      body_moves_mm.size(),
      hand_moves_mm.size(),
      off_median,
      InterpolatedQuantile(off_plane_mm, 0.95),
      move_median,
      body_moves_mm.empty() ? NAN : Median(body_moves_mm),
      hand_moves_mm.empty() ? NAN : Median(hand_moves_mm));
  const char* part_names[3] = {"body", "left hand", "right hand"};
  std::array<double, 3> part_p90{};
  for (int part = 0; part < 3; ++part) {
    const std::vector<double>& d = part_off_plane_mm[part];
    part_p90[part] = d.empty() ? NAN : InterpolatedQuantile(d, 0.9);
    std::printf(
        "plane test: %s off the plane median %.1f mm, 90th percentile %.1f mm (%zu points)\n",
        part_names[part],
        d.empty() ? NAN : Median(d),
        part_p90[part],
        d.size());
  }
  // Issue 28: the bowing hand within 30 mm of the plane at the 90th percentile (49 mm
  // before the check across views), the body and the left hand no worse (23.5 and 2.6 mm).
  EXPECT_LE(part_p90[2], 30.0);
  EXPECT_LE(part_p90[0], 25.0);
  EXPECT_LE(part_p90[1], 4.0);
  EXPECT_GE(body_moves_mm.size(), 12u);  // the body's points
  EXPECT_GE(hand_points_seen, 21);       // at least one whole hand
  EXPECT_LE(off_median, 12.0);
  EXPECT_LE(move_median, 6.0);
}

}  // namespace
}  // namespace arco::capture
