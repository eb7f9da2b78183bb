// Synthetic multi-view set-ups with known truth, for tests and benchmarks:
// an SPD-like ring of cameras and noisy, partly wrong 2D detections of known 3D points.
#pragma once

#include <cstdint>

#include "arco/camera/rig.h"
#include "arco/util/npy.h"

namespace arco::testing {

struct SyntheticRigOptions {
  int num_cameras = 20;
  double radius_m = 3.0;         // ring radius around the origin
  double height_spread_m = 0.8;  // camera heights alternate within +-spread/2 around 1.2 m
  bool distortion = true;        // SPD-like radial/tangential distortion
  uint64_t seed = 1;             // small pose jitter
};

// Cameras 2300x2656 px, f = 2260 px, looking at (0, 0, 1) m; units "m".
Rig MakeSyntheticRig(const SyntheticRigOptions& options);

struct SyntheticDetectionOptions {
  double noise_px = 1.0;                    // Gaussian pixel noise (std per axis)
  double outlier_fraction = 0.0;            // detections moved 40..400 px away, with high scores
  double missing_fraction = 0.0;            // detections removed (NaN), as for occlusions
  double min_score = 0.6, max_score = 1.0;  // scores of good detections, uniform
  uint64_t seed = 2;
};

// Random points in a performer-sized box around (0, 0, 1) m: (frames, points, 3),
// moving smoothly over frames.
NpyArray<double> MakeSyntheticPoints(int64_t frames, int64_t points, uint64_t seed);

// Projects (F, P, 3) points into every camera: (F, V, P, 3) [x, y, score].
NpyArray<double> MakeSyntheticDetections(const Rig& rig,
                                         const NpyArray<double>& points3d,
                                         const SyntheticDetectionOptions& options);

}  // namespace arco::testing
