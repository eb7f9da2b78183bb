#include "arco/mocap/triangulate_sequence.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstring>

#include "arco/testing/synthetic_views.h"

namespace arco {
namespace {

struct Scene {
  Rig rig;
  NpyArray<double> truth;
  NpyArray<double> detections;
  std::vector<int> view_to_camera;
};

Scene MakeScene(int cameras, int frames, int points, double outliers, double missing) {
  Scene s;
  testing::SyntheticRigOptions rig_options;
  rig_options.num_cameras = cameras;
  s.rig = testing::MakeSyntheticRig(rig_options);
  s.truth = testing::MakeSyntheticPoints(frames, points, 11);
  testing::SyntheticDetectionOptions d;
  d.noise_px = 1.0;
  d.outlier_fraction = outliers;
  d.missing_fraction = missing;
  s.detections = testing::MakeSyntheticDetections(s.rig, s.truth, d);
  for (int c = 0; c < cameras; ++c) s.view_to_camera.push_back(c);
  return s;
}

TEST(TriangulateSequence, RecoversTruthWithOutliersAndOcclusions) {
  const Scene s = MakeScene(20, 6, 40, 0.05, 0.2);
  SequenceTriangulationOptions options;
  options.num_threads = 2;
  struct CountFrames : Progress {
    std::atomic<int64_t> frames_done{0};
    void Advance(int64_t n) override { frames_done += n; }
  } progress;
  auto r = TriangulateSequence(s.rig, s.view_to_camera, s.detections, options, &progress);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(progress.frames_done.load(), 6);
  ASSERT_EQ(r->points3d.shape, (std::vector<int64_t>{6, 40, 3}));
  double max_err = 0;
  for (int64_t f = 0; f < 6; ++f) {
    for (int64_t p = 0; p < 40; ++p) {
      Eigen::Vector3d x, t;
      for (int k = 0; k < 3; ++k) {
        x[k] = r->points3d.at(f, p, k);
        t[k] = s.truth.at(f, p, k);
      }
      ASSERT_TRUE(x.allFinite());
      max_err = std::max(max_err, (x - t).norm());
      EXPECT_GE(r->num_inliers.at(f, p), 2);
      EXPECT_LE(r->num_inliers.at(f, p), r->num_views.at(f, p));
      int mask_count = 0;
      for (int v = 0; v < 20; ++v) mask_count += r->inlier_mask.at(f, p, v);
      EXPECT_EQ(mask_count, r->num_inliers.at(f, p));
    }
  }
  EXPECT_LT(max_err, 3e-3);  // metres, with 1 px noise
  const auto summary = Summarize(*r);
  EXPECT_EQ(summary.triangulated, 240);
  EXPECT_EQ(summary.points, 240);
  EXPECT_GT(summary.median_rms_reprojection_px, 0.7);
  EXPECT_LT(summary.median_rms_reprojection_px, 1.6);
}

TEST(TriangulateSequence, IdenticalForAnyThreadCount) {
  const Scene s = MakeScene(12, 9, 15, 0.1, 0.1);
  SequenceTriangulationOptions one;
  one.num_threads = 1;
  SequenceTriangulationOptions three = one;
  three.num_threads = 3;
  auto a = TriangulateSequence(s.rig, s.view_to_camera, s.detections, one);
  auto b = TriangulateSequence(s.rig, s.view_to_camera, s.detections, three);
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a->points3d.data.size(), b->points3d.data.size());
  EXPECT_EQ(0,
            std::memcmp(a->points3d.data.data(),
                        b->points3d.data.data(),
                        a->points3d.data.size() * sizeof(double)));
  EXPECT_EQ(a->inlier_mask.data, b->inlier_mask.data);
}

TEST(TriangulateSequence, MissingViewsGiveNaN) {
  Scene s = MakeScene(4, 2, 3, 0.0, 0.0);
  // Point 1 of frame 0 seen by one camera only.
  for (int v = 1; v < 4; ++v) s.detections.at(0, v, 1, 0) = NAN;
  auto r = TriangulateSequence(s.rig, s.view_to_camera, s.detections, {});
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(std::isnan(r->points3d.at(0, 1, 0)));
  EXPECT_TRUE(std::isnan(r->rms_reprojection_px.at(0, 1)));
  EXPECT_EQ(r->num_views.at(0, 1), 1);
  EXPECT_EQ(r->num_inliers.at(0, 1), 0);
  EXPECT_FALSE(std::isnan(r->points3d.at(1, 1, 0)));
  EXPECT_EQ(Summarize(*r).triangulated, 5);
}

TEST(TriangulateSequence, ShapeAndViewErrorsAreReported) {
  const Scene s = MakeScene(3, 1, 2, 0.0, 0.0);
  NpyArray<double> bad = s.detections;
  bad.shape = {1, 3, 6};
  auto r = TriangulateSequence(s.rig, s.view_to_camera, bad, {}, {}, "k.npy");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("k.npy"), std::string::npos);
  r = TriangulateSequence(s.rig, {0, 1}, s.detections, {});
  EXPECT_FALSE(r.ok());
  r = TriangulateSequence(s.rig, {0, 1, 5}, s.detections, {});
  EXPECT_FALSE(r.ok());
  r = TriangulateSequence(s.rig, {0, 1, 1}, s.detections, {});
  EXPECT_FALSE(r.ok());
  SequenceTriangulationOptions o;
  o.num_threads = -2;
  EXPECT_FALSE(TriangulateSequence(s.rig, s.view_to_camera, s.detections, o).ok());
}

}  // namespace
}  // namespace arco
