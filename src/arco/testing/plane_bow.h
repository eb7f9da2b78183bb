// A bow for the tracking tests and benchmarks (capture_track_bow_test, track_bench's
// BM_TrackBow): its texture as a plane of the plane scene (plane_scene.h) and a bowing
// motion with known truth.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "arco/geometry/transform.h"
#include "arco/testing/plane_scene.h"

namespace arco::testing {

// Frog and tip on the bow texture's axis (texture pixels; 1 px = 1 mm).
inline const Eigen::Vector2d kBowFrogPx(20, 11.5), kBowTipPx(700, 11.5);

// A 720 x 24 mm strip, 1 px per mm, mipmapped: random grey blocks of 6 mm (40..220,
// seeded), or `plain`: grey 120, the frog black over 60 mm with a light 10 mm eye, the
// last 25 mm white.
PlaneTexture MakeBowTexture(bool plain = false, uint32_t seed = 7);

// world_from_bow per frame: strokes of +-200 mm along the bow at 0.7 Hz and string
// crossings (the bow turned +-10 degrees about the world's y axis at 0.35 Hz), about the
// plane's rest pose moved to (0, -200, -150) mm.
std::vector<Rigid3d> MakeBowingMotion(int frames, double fps_hz = 30);

}  // namespace arco::testing
