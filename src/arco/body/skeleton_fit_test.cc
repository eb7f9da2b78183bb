#include "arco/body/skeleton_fit.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include "arco/testing/skeleton_take.h"
#include "arco/util/stats.h"

namespace arco::body {
namespace {

using testing::MakeTake;
using testing::Take;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

int Index(const Take& t, const std::string& name) {
  return static_cast<int>(std::find(t.names.begin(), t.names.end(), name) - t.names.begin());
}

// Equal bit for bit (NaN included).
bool SameBits(const NpyArray<double>& a, const NpyArray<double>& b) {
  return a.shape == b.shape &&
         std::memcmp(a.data.data(), b.data.data(), a.data.size() * sizeof(double)) == 0;
}

double Distance(const NpyArray<double>& p, int64_t f, int a, int b) {
  Eigen::Vector3d d;
  for (int c = 0; c < 3; ++c) d[c] = p.at(f, a, c) - p.at(f, b, c);
  return d.norm();
}

TEST(FitSkeleton, RecoversBoneLengthsAndBeatsTheRawPoints) {
  const int frames = 120;
  const Take t = MakeTake(frames, 2.0, 7);
  SkeletonFitOptions options;
  const StatusOr<SkeletonFitResult> fit = FitSkeleton(t.noisy, t.names, {}, options);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  ASSERT_EQ(fit->fitted_groups.size(), 2u);
  const NpyArray<double>& out = fit->points_mm;

  const std::vector<SkeletonJoint>& s = WholeBodySkeleton();
  std::vector<double> raw_error, fit_error;
  int filled = 0;
  for (int f = 0; f < frames; ++f) {
    for (const SkeletonJoint& j : s) {
      if (j.keypoint.empty() || j.group == JointGroup::kLeftHand) continue;
      const int k = Index(t, j.keypoint);
      const double e = Distance(out, f, k, k);  // 0 unless NaN
      ASSERT_TRUE(std::isfinite(e)) << j.name << " frame " << f << " not filled";
      Eigen::Vector3d fitted, truth, raw;
      for (int c = 0; c < 3; ++c) {
        fitted[c] = out.at(f, k, c);
        truth[c] = t.truth.at(f, k, c);
        raw[c] = t.noisy.at(f, k, c);
      }
      fit_error.push_back((fitted - truth).norm());
      if (raw.allFinite()) {
        raw_error.push_back((raw - truth).norm());
      } else {
        ++filled;
      }
    }
  }
  EXPECT_GT(filled, 50);  // missing points were filled from the skeleton
  const double raw_median = Median(raw_error), fit_median = Median(fit_error);
  EXPECT_GT(raw_median, 2.5);  // 2 mm per axis: about 3.1 mm in 3D
  EXPECT_LT(fit_median, 0.85 * raw_median) << "raw " << raw_median << " fit " << fit_median;

  // Every bone has one length over the take, within 1 mm of the truth's.
  for (const SkeletonJoint& j : s) {
    if (j.keypoint.empty() || j.parent < 0 || j.group == JointGroup::kLeftHand) continue;
    const SkeletonJoint& parent = s[j.parent];
    if (parent.keypoint.empty() || j.positioned) continue;
    const int a = Index(t, j.keypoint), b = Index(t, parent.keypoint);
    const double truth = Distance(t.truth, 0, a, b);
    const double first = Distance(out, 0, a, b);
    EXPECT_NEAR(first, truth, 1.0) << j.name;
    for (int f = 1; f < frames; ++f) ASSERT_NEAR(Distance(out, f, a, b), first, 1e-9) << j.name;
  }
  // The left hand (not asked for) is untouched.
  const int tip = Index(t, "left_hand_index_tip");
  for (int f = 0; f < frames; ++f) {
    for (int c = 0; c < 3; ++c) {
      const double a = out.at(f, tip, c), b = t.noisy.at(f, tip, c);
      ASSERT_TRUE(a == b || (std::isnan(a) && std::isnan(b)));
    }
  }
}

TEST(FitSkeleton, ExactOnExactPointsAndDeterministic) {
  const Take t = MakeTake(30, 0.0, 11);
  NpyArray<double> clean = t.truth;
  const StatusOr<SkeletonFitResult> a = FitSkeleton(clean, t.names, {}, SkeletonFitOptions{});
  const StatusOr<SkeletonFitResult> b = FitSkeleton(clean, t.names, {}, SkeletonFitOptions{});
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_TRUE(SameBits(a->points_mm, b->points_mm));
  double worst = 0;
  for (size_t i = 0; i < clean.data.size(); ++i) {
    worst = std::max(worst, std::abs(a->points_mm.data[i] - clean.data[i]));
  }
  EXPECT_LT(worst, 1e-6);
}

// The chunk tests' fit: chunks of 7 frames (of a 60-frame take: 9 chunks, the last one
// short) on `threads` threads.
SkeletonFitOptions SevenFrameChunks(int threads) {
  SkeletonFitOptions o;
  o.chunk_frames = 7;
  o.num_threads = threads;
  return o;
}

// Chunks fitted in parallel: the same bits for any thread count.
TEST(FitSkeleton, ChunksGiveTheSameBitsForAnyThreadCount) {
  const Take t = MakeTake(60, 2.0, 5);
  SkeletonFitOptions o = SevenFrameChunks(1);
  const StatusOr<SkeletonFitResult> one = FitSkeleton(t.noisy, t.names, {}, o);
  ASSERT_TRUE(one.ok()) << one.status().message();
  for (int threads : {2, 3, 0}) {
    o.num_threads = threads;
    const StatusOr<SkeletonFitResult> many = FitSkeleton(t.noisy, t.names, {}, o);
    ASSERT_TRUE(many.ok());
    EXPECT_TRUE(SameBits(one->points_mm, many->points_mm)) << threads << " threads";
    EXPECT_EQ(one->median_residual_mm, many->median_residual_mm);
  }
  o.chunk_frames = 0;
  EXPECT_FALSE(FitSkeleton(t.noisy, t.names, {}, o).ok());
  o.chunk_frames = 7;
  o.num_threads = -1;
  EXPECT_FALSE(FitSkeleton(t.noisy, t.names, {}, o).ok());
}

// Chunk starts (cold, from the tree fit, then the warm-up) agree with one warm-started pass
// over the whole take. (Its bound moves with the compiler: the Makefile's
// ASAN_COMPILER_SENSITIVE says by how much.)
TEST(FitSkeleton, ChunkStartsAgreeWithOnePassOverTheTake) {
  const Take t = MakeTake(60, 2.0, 5);
  const StatusOr<SkeletonFitResult> one = FitSkeleton(t.noisy, t.names, {}, SevenFrameChunks(1));
  ASSERT_TRUE(one.ok()) << one.status().message();
  SkeletonFitOptions whole;
  whole.chunk_frames = 60;
  const StatusOr<SkeletonFitResult> warm = FitSkeleton(t.noisy, t.names, {}, whole);
  ASSERT_TRUE(warm.ok());
  EXPECT_FALSE(SameBits(one->points_mm, warm->points_mm));  // the chunks did start cold
  // Measured joints agree. A filled (missing) joint is as undetermined as the pose it
  // inherits (an elbow missing between a measured shoulder and wrist may swivel), so
  // there the chunks must only be as close to the truth as one pass.
  double worst_measured = 0;
  std::vector<double> filled_chunks, filled_one_pass;
  for (size_t i = 0; i < warm->points_mm.data.size(); i += 3) {
    const double a = one->points_mm.data[i], b = warm->points_mm.data[i];
    ASSERT_EQ(std::isnan(a), std::isnan(b)) << i;
    if (std::isnan(a)) continue;
    const Eigen::Map<const Eigen::Vector3d> chunks(&one->points_mm.data[i]),
        pass(&warm->points_mm.data[i]), truth(&t.truth.data[i]);
    if (std::isnan(t.noisy.data[i])) {
      filled_chunks.push_back((chunks - truth).norm());
      filled_one_pass.push_back((pass - truth).norm());
    } else {
      worst_measured = std::max(worst_measured, (chunks - pass).norm());
    }
  }
  EXPECT_LT(worst_measured, 0.05) << "mm";
  ASSERT_GT(filled_chunks.size(), 100u);
  EXPECT_LT(Median(filled_chunks), 1.05 * Median(filled_one_pass) + 0.05)
      << Median(filled_one_pass) << " mm in one pass";
}

TEST(FitSkeleton, RejectsBadShapesAndLeavesUnmeasuredGroupsRaw) {
  Take t = MakeTake(5, 1.0, 3);
  NpyArray<double> bad = t.noisy;
  bad.shape = {5, static_cast<int64_t>(t.names.size()) - 1, 3};
  EXPECT_FALSE(FitSkeleton(bad, t.names, {}, SkeletonFitOptions{}).ok());
  SkeletonFitOptions o;
  o.robust_scale_mm = 0;
  EXPECT_FALSE(FitSkeleton(t.noisy, t.names, {}, o).ok());
  // No feet in the capture (a COCO-17 import): the rest of the body is still fitted.
  Take nofeet = t;
  for (const char* foot : {"left_big_toe",
                           "left_small_toe",
                           "left_heel",
                           "right_big_toe",
                           "right_small_toe",
                           "right_heel"}) {
    for (int f = 0; f < 5; ++f) {
      for (int c = 0; c < 3; ++c) nofeet.noisy.at(f, Index(t, foot), c) = kNaN;
    }
  }
  const StatusOr<SkeletonFitResult> feet =
      FitSkeleton(nofeet.noisy, t.names, {}, SkeletonFitOptions{});
  ASSERT_TRUE(feet.ok());
  ASSERT_EQ(feet->fitted_groups.size(), 2u);
  const int knee = Index(t, "left_knee");
  EXPECT_NE(feet->points_mm.at(1, knee, 0), t.noisy.at(1, knee, 0));  // fitted
  EXPECT_TRUE(std::isnan(feet->points_mm.at(1, Index(t, "left_heel"), 0)));
  // Weights: 1 everywhere is no weighting; weight 0 is a missing point.
  NpyArray<double> ones;
  ones.shape = {5, static_cast<int64_t>(t.names.size())};
  ones.data.assign(5 * t.names.size(), 1.0);
  const StatusOr<SkeletonFitResult> unweighted = FitSkeleton(t.noisy, t.names, {}, {});
  const StatusOr<SkeletonFitResult> weighted = FitSkeleton(t.noisy, t.names, ones, {});
  ASSERT_TRUE(unweighted.ok() && weighted.ok());
  EXPECT_TRUE(SameBits(unweighted->points_mm, weighted->points_mm));
  NpyArray<double> holes = t.noisy;
  NpyArray<double> zero = ones;
  zero.at(3, knee) = 0;
  for (int c = 0; c < 3; ++c) holes.at(3, knee, c) = kNaN;
  const StatusOr<SkeletonFitResult> a = FitSkeleton(holes, t.names, {}, {});
  const StatusOr<SkeletonFitResult> b = FitSkeleton(t.noisy, t.names, zero, {});
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->points_mm.at(3, knee, 0), b->points_mm.at(3, knee, 0));
  EXPECT_EQ(a->points_mm.at(4, Index(t, "nose"), 1), b->points_mm.at(4, Index(t, "nose"), 1));
  EXPECT_FALSE(FitSkeleton(t.noisy, t.names, NpyArray<double>{{5, 3}, {}}, {}).ok());

  // The right hand never seen: the body is fitted, the hand stays NaN.
  const int first = Index(t, "right_hand_wrist");
  for (int f = 0; f < 5; ++f) {
    for (int k = first; k < first + 21; ++k) {
      for (int c = 0; c < 3; ++c) t.noisy.at(f, k, c) = kNaN;
    }
  }
  const StatusOr<SkeletonFitResult> fit = FitSkeleton(t.noisy, t.names, {}, SkeletonFitOptions{});
  ASSERT_TRUE(fit.ok());
  ASSERT_EQ(fit->fitted_groups.size(), 1u);
  EXPECT_EQ(fit->fitted_groups[0], JointGroup::kBody);
  EXPECT_TRUE(std::isnan(fit->points_mm.at(2, first + 5, 0)));
}

}  // namespace
}  // namespace arco::body
