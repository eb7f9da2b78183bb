// A seeded random generator whose draws are identical on every platform and
// standard library (std::normal_distribution is implementation-defined), so a
// synthetic capture is the same bit for bit for a given seed everywhere.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

namespace arco::synth {

class Rng {
 public:
  explicit Rng(uint64_t seed) : engine_(seed) {}
  // A generator for an independent stream (e.g. one per camera), derived from
  // this seed and `stream` with SplitMix64 so streams do not overlap in practice.
  static Rng Stream(uint64_t seed, uint64_t stream) {
    uint64_t z = seed + 0x9e3779b97f4a7c15ULL * (stream + 1);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return Rng(z ^ (z >> 31));
  }
  // Uniform in [0, 1) with 53 random bits.
  double Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  // Standard normal (Box-Muller; one value per call for simplicity).
  double Normal() {
    double u1 = Uniform();
    while (u1 <= 0) u1 = Uniform();
    const double u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
  }
  double Normal(double mean, double sigma) { return mean + sigma * Normal(); }
  bool Bernoulli(double p) { return Uniform() < p; }
  // Integer in [0, n).
  int UniformInt(int n) { return static_cast<int>(Uniform() * n); }

 private:
  std::mt19937_64 engine_;
};

}  // namespace arco::synth
