// A synthetic performer for the skeleton fit's tests and benchmark (test support: see
// CMakeLists.txt): a performer of body::WholeBodySkeleton()'s shape with random bone
// lengths, moving smoothly.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "arco/util/npy.h"

namespace arco::testing {

// A performer of the skeleton's shape with random bone lengths (a rigid shape per branching
// joint), moving smoothly over `frames` frames: the truth, and the truth with Gaussian
// noise, a few gross outliers and missing points.
struct Take {
  std::vector<std::string> names;
  NpyArray<double> truth, noisy;
};

Take MakeTake(int frames, double noise_mm, uint32_t seed);

}  // namespace arco::testing
