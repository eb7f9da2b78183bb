// Minimum-cost path through a chain of steps, each with its own candidate states
// (Viterbi / dynamic programming over a trellis). Used by the fingering planner
// (synth/fingering.cc) and the string/finger decode (refine/arco_decode.cc).
//
// Cost of a path s_0..s_{n-1} = emission(0, s_0) + sum over t >= 1 of
//   transition(t, s_{t-1}, s_t) + emission(t, s_t).
// The recursion adds in exactly this order: best_t(k) = min_j (best_{t-1}(j) +
// transition(t, j, k)) + emission(t, k), so callers that switch to it keep their sums
// bit for bit. Ties go to the LOWER state index, both in the recursion and at the end
// (a strict < scan from index 0), so plans are deterministic.
#pragma once

#include <functional>
#include <limits>
#include <stdexcept>
#include <vector>

namespace arco {

struct ViterbiPath {
  std::vector<int> states;  // chosen state per step (empty for no steps)
  double total_cost = 0;    // cost of that path (+inf when every path is infinite)
};

// num_states[t] > 0 candidates at step t (throws std::invalid_argument otherwise);
// emission(t, k) and transition(t, j, k) (from state j at t - 1 to state k at t) return
// costs, called once per (t, k) and per (t, j, k). NaN costs never win a comparison;
// where no predecessor has a finite cost, state 0 is taken as the predecessor.
template <typename EmissionFn, typename TransitionFn>
ViterbiPath DecodeViterbi(const std::vector<int>& num_states,
                          EmissionFn&& emission,
                          TransitionFn&& transition) {
  const size_t n = num_states.size();
  ViterbiPath path;
  if (n == 0) return path;
  for (int count : num_states) {
    if (count <= 0) throw std::invalid_argument("DecodeViterbi: a step without states");
  }
  std::vector<std::vector<double>> best(n);
  std::vector<std::vector<int>> back(n);
  best[0].resize(static_cast<size_t>(num_states[0]));
  for (int k = 0; k < num_states[0]; ++k) best[0][static_cast<size_t>(k)] = emission(size_t{0}, k);
  for (size_t t = 1; t < n; ++t) {
    const std::vector<double>& prev = best[t - 1];
    best[t].assign(static_cast<size_t>(num_states[t]), std::numeric_limits<double>::infinity());
    back[t].assign(static_cast<size_t>(num_states[t]), 0);
    for (int k = 0; k < num_states[t]; ++k) {
      double& b = best[t][static_cast<size_t>(k)];
      for (int j = 0; j < num_states[t - 1]; ++j) {
        const double c = prev[static_cast<size_t>(j)] + transition(t, j, k);
        if (c < b) {
          b = c;
          back[t][static_cast<size_t>(k)] = j;
        }
      }
      b += emission(t, k);
    }
  }
  const std::vector<double>& last = best[n - 1];
  int k = 0;
  for (size_t j = 1; j < last.size(); ++j) {
    if (last[j] < last[static_cast<size_t>(k)]) k = static_cast<int>(j);
  }
  path.total_cost = last[static_cast<size_t>(k)];
  path.states.resize(n);
  for (size_t t = n; t-- > 0;) {
    path.states[t] = k;
    if (t > 0) k = back[t][static_cast<size_t>(k)];
  }
  return path;
}

}  // namespace arco
