// Hand model benchmarks (docs/performance.md, section "Hand"): per-frame
// multi-view fit, single-finger IK, fusion and graft, each beside a baseline
// measured in the same run (linear DLT of the 21 keypoints; forward kinematics).
#include <benchmark/benchmark.h>

#include <random>

#include "arco/geometry/triangulation.h"
#include "arco/hand/fit.h"
#include "arco/hand/fusion.h"
#include "arco/hand/graft.h"
#include "arco/hand/hand_test_util.h"
#include "arco/hand/ik.h"
#include "arco/hand/synthetic_rig.h"

namespace arco::hand {
namespace {

struct Frames {
  std::vector<Camera> cameras;
  std::vector<HandPose> truth;
  std::vector<std::vector<HandKeypoints2d>> views;
};

Frames MakeFrames(int num_cameras, int num_frames) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::mt19937 rng(1);
  Frames f;
  f.cameras = testing::MakeRingRig(num_cameras, 2500, Eigen::Vector3d::Zero());
  for (int i = 0; i < num_frames; ++i) {
    f.truth.push_back(testing::RandomPose(model, rng, 0.05));
    f.views.push_back(
        testing::ProjectHand(f.cameras, ForwardKinematics(model, f.truth.back()), 2.0, 0.05, rng));
  }
  return f;
}

// Baseline: confidence-weighted DLT of all 21 keypoints (the authors' kind of
// per-frame triangulation, without RANSAC).
void BM_TriangulateDlt21(benchmark::State& state) {
  const Frames f = MakeFrames(static_cast<int>(state.range(0)), 16);
  std::vector<Eigen::Vector3d> centers;
  for (const Camera& c : f.cameras) centers.push_back(c.CenterInWorld());
  const WorldConditioning cond = ConditioningFromCameraCenters(centers);
  size_t i = 0;
  for (auto _ : state) {
    const auto& views = f.views[i++ % f.views.size()];
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      std::vector<DltObservation> obs;
      for (size_t v = 0; v < views.size(); ++v) {
        DltObservation o;
        o.projection << f.cameras[v].cam_from_world.rotation,
            f.cameras[v].cam_from_world.translation;
        o.point = f.cameras[v].PixelToNormalized(views[v].pixels[k]);
        o.weight = views[v].scores[k];
        obs.push_back(o);
      }
      benchmark::DoNotOptimize(TriangulateDlt(obs, cond));
    }
  }
}
BENCHMARK(BM_TriangulateDlt21)->Arg(8)->Arg(20)->Unit(benchmark::kMicrosecond);

// Per-frame multi-view fit. range(1) = 0: tracking (previous frame = a pose
// 2 degrees per joint away); 1: from scratch (own triangulation + 3D fit).
void BM_FitHandMultiView(benchmark::State& state) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  const Frames f = MakeFrames(static_cast<int>(state.range(0)), 16);
  size_t i = 0;
  for (auto _ : state) {
    const size_t j = i++ % f.views.size();
    HandFitInit init;
    if (state.range(1) == 0) {
      HandPose previous = f.truth[j];
      for (double& a : previous.angles_rad) a += 0.035;
      init.previous_pose = ClampToLimits(model, previous);
    }
    benchmark::DoNotOptimize(
        FitHandMultiView(model, f.cameras, f.views[j], init, HandFitOptions{}));
  }
}
BENCHMARK(BM_FitHandMultiView)
    ->Args({8, 0})
    ->Args({20, 0})
    ->Args({8, 1})
    ->Args({20, 1})
    ->Unit(benchmark::kMicrosecond);

// Baseline for IK: one forward kinematics of the whole hand.
void BM_ForwardKinematics(benchmark::State& state) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::mt19937 rng(2);
  const HandPose pose = testing::RandomPose(model, rng);
  for (auto _ : state) benchmark::DoNotOptimize(ForwardKinematics(model, pose));
}
BENCHMARK(BM_ForwardKinematics);

// Single-finger IK. range(0): FingerIkJoints; range(1) = 0: reachable target
// (the free joints of the index finger re-drawn), 1: the same target moved 10 mm
// radially (generally unreachable: restarts run).
void BM_FingertipIk(benchmark::State& state) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::mt19937 rng(3);
  std::vector<HandPose> refs;
  std::vector<Eigen::Vector3d> targets;
  for (int i = 0; i < 32; ++i) {
    const HandPose ref = testing::RandomPose(model, rng, 0.1);
    HandPose other = testing::RandomPose(model, rng, 0.1);
    other.world_from_wrist.rotation = ref.world_from_wrist.rotation;
    other.world_from_wrist.translation = ref.world_from_wrist.translation;
    // Only the index finger's free joints differ, so the target is reachable.
    std::vector<bool> free(kNumJointDofs, false);
    for (FingerDof slot : FreeDofs(static_cast<FingerIkJoints>(state.range(0)))) {
      free[DofIndex(Finger::kIndex, slot)] = true;
    }
    for (int d = 0; d < kNumJointDofs; ++d) {
      if (!free[d]) other.angles_rad[d] = ref.angles_rad[d];
    }
    Eigen::Vector3d target = FingertipInWorld(model, other, Finger::kIndex);
    if (state.range(1) == 1) target += ref.world_from_wrist.rotation * Eigen::Vector3d(10, 0, 0);
    refs.push_back(ref);
    targets.push_back(target);
  }
  FingerIkOptions options;
  options.joints = static_cast<FingerIkJoints>(state.range(0));
  size_t i = 0;
  for (auto _ : state) {
    const size_t j = i++ % refs.size();
    benchmark::DoNotOptimize(SolveFingertipIk(model, refs[j], Finger::kIndex, targets[j], options));
  }
}
BENCHMARK(BM_FingertipIk)
    ->Args({0, 0})
    ->Args({0, 1})
    ->Args({2, 0})
    ->Args({2, 1})
    ->Unit(benchmark::kMicrosecond);

void BM_FuseViewHands(benchmark::State& state) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  const auto cameras =
      testing::MakeRingRig(static_cast<int>(state.range(0)), 2500, Eigen::Vector3d::Zero());
  std::mt19937 rng(4);
  std::normal_distribution<double> n(0.0, 1.0);
  const HandPose truth = testing::RandomPose(model, rng, 0.1);
  const HandPointsMm world = ForwardKinematics(model, truth);
  std::vector<ViewHand3d> views(cameras.size());
  for (size_t v = 0; v < cameras.size(); ++v) {
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      views[v].points_in_camera_mm[k] =
          cameras[v].PointInCamera(world[k]) + 3.0 * Eigen::Vector3d(n(rng), n(rng), n(rng));
    }
  }
  for (auto _ : state)
    benchmark::DoNotOptimize(FuseViewHands(model, cameras, views, HandFusionOptions{}));
}
BENCHMARK(BM_FuseViewHands)->Arg(12)->Unit(benchmark::kMicrosecond);

void BM_GraftHandAtWrist(benchmark::State& state) {
  const HandModel model = HandModel::Default(HandSide::kLeft);
  std::mt19937 rng(5);
  const HandPose hand = testing::RandomPose(model, rng, 0.1);
  HandPointsMm body = ForwardKinematics(model, testing::RandomPose(model, rng, 0.1));
  for (auto _ : state)
    benchmark::DoNotOptimize(GraftHandAtWrist(model, hand, body, {}, WristGraftOptions{}));
}
BENCHMARK(BM_GraftHandAtWrist)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace arco::hand

BENCHMARK_MAIN();
