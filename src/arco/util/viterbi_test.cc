#include "arco/util/viterbi.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace arco {
namespace {

struct Problem {
  std::vector<int> num_states;
  std::vector<std::vector<double>> emission;                 // [t][k]
  std::vector<std::vector<std::vector<double>>> transition;  // [t][j][k], t >= 1
};

// Small integer costs so that ties are frequent and sums are exact.
Problem RandomProblem(std::mt19937* rng) {
  std::uniform_int_distribution<int> steps(1, 5), states(1, 4), cost(0, 3);
  Problem p;
  p.num_states.resize(static_cast<size_t>(steps(*rng)));
  for (int& n : p.num_states) n = states(*rng);
  const size_t n = p.num_states.size();
  p.emission.resize(n);
  p.transition.resize(n);
  for (size_t t = 0; t < n; ++t) {
    for (int k = 0; k < p.num_states[t]; ++k) p.emission[t].push_back(cost(*rng));
    if (t == 0) continue;
    p.transition[t].assign(static_cast<size_t>(p.num_states[t - 1]), {});
    for (auto& row : p.transition[t]) {
      for (int k = 0; k < p.num_states[t]; ++k) row.push_back(cost(*rng));
    }
  }
  return p;
}

double PathCost(const Problem& p, const std::vector<int>& s) {
  double c = p.emission[0][static_cast<size_t>(s[0])];
  for (size_t t = 1; t < s.size(); ++t) {
    c += p.transition[t][static_cast<size_t>(s[t - 1])][static_cast<size_t>(s[t])];
    c += p.emission[t][static_cast<size_t>(s[t])];
  }
  return c;
}

ViterbiPath Decode(const Problem& p) {
  return DecodeViterbi(
      p.num_states,
      [&](size_t t, int k) { return p.emission[t][static_cast<size_t>(k)]; },
      [&](size_t t, int j, int k) {
        return p.transition[t][static_cast<size_t>(j)][static_cast<size_t>(k)];
      });
}

// Every path in the order of its LAST step first (reversed lexicographic order), the
// order in which the decoder's tie-breaking resolves equal costs: a lower final state
// wins, then the lower predecessor of it, and so on back to the start.
void Enumerate(const Problem& p, std::vector<int>* path, std::vector<std::vector<int>>* out) {
  const size_t t = path->size();
  if (t == p.num_states.size()) {
    out->push_back(*path);
    return;
  }
  for (int k = 0; k < p.num_states[t]; ++k) {
    path->push_back(k);
    Enumerate(p, path, out);
    path->pop_back();
  }
}

TEST(DecodeViterbi, MatchesBruteForceOnSmallRandomProblems) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 500; ++trial) {
    const Problem p = RandomProblem(&rng);
    std::vector<std::vector<int>> all;
    std::vector<int> scratch;
    Enumerate(p, &scratch, &all);
    double best = std::numeric_limits<double>::infinity();
    for (const auto& s : all) best = std::min(best, PathCost(p, s));
    const ViterbiPath path = Decode(p);
    ASSERT_EQ(path.states.size(), p.num_states.size());
    EXPECT_EQ(path.total_cost, best) << "trial " << trial;
    EXPECT_EQ(PathCost(p, path.states), best) << "trial " << trial;
  }
}

// Ties: among the cheapest paths the decoder takes the lowest final state, and at each
// earlier step the lowest predecessor that reaches the chosen state at the best cost.
TEST(DecodeViterbi, TiesGoToTheLowerStateIndex) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 500; ++trial) {
    const Problem p = RandomProblem(&rng);
    const size_t n = p.num_states.size();
    const ViterbiPath path = Decode(p);
    // Recompute the per-step best costs by brute force over prefixes.
    std::vector<std::vector<double>> best(n);
    for (size_t t = 0; t < n; ++t) {
      best[t].assign(static_cast<size_t>(p.num_states[t]), std::numeric_limits<double>::infinity());
    }
    for (int k = 0; k < p.num_states[0]; ++k)
      best[0][static_cast<size_t>(k)] = p.emission[0][static_cast<size_t>(k)];
    for (size_t t = 1; t < n; ++t) {
      for (int k = 0; k < p.num_states[t]; ++k) {
        for (int j = 0; j < p.num_states[t - 1]; ++j) {
          best[t][static_cast<size_t>(k)] =
              std::min(best[t][static_cast<size_t>(k)],
                       best[t - 1][static_cast<size_t>(j)] +
                           p.transition[t][static_cast<size_t>(j)][static_cast<size_t>(k)] +
                           p.emission[t][static_cast<size_t>(k)]);
        }
      }
    }
    const auto& last = best[n - 1];
    const int lowest_final =
        static_cast<int>(std::min_element(last.begin(), last.end()) - last.begin());
    EXPECT_EQ(path.states[n - 1], lowest_final);
    for (size_t t = n - 1; t > 0; --t) {
      const int k = path.states[t];
      int lowest = -1;
      for (int j = 0; j < p.num_states[t - 1] && lowest < 0; ++j) {
        if (best[t - 1][static_cast<size_t>(j)] +
                p.transition[t][static_cast<size_t>(j)][static_cast<size_t>(k)] +
                p.emission[t][static_cast<size_t>(k)] ==
            best[t][static_cast<size_t>(k)]) {
          lowest = j;
        }
      }
      EXPECT_EQ(path.states[t - 1], lowest) << "trial " << trial << " step " << t;
    }
  }
}

TEST(DecodeViterbi, EmptyChainAndStepWithoutStates) {
  const ViterbiPath empty = DecodeViterbi(
      {}, [](size_t, int) { return 0.0; }, [](size_t, int, int) { return 0.0; });
  EXPECT_TRUE(empty.states.empty());
  EXPECT_EQ(empty.total_cost, 0);
  EXPECT_THROW(DecodeViterbi(
                   {2, 0}, [](size_t, int) { return 0.0; }, [](size_t, int, int) { return 0.0; }),
               std::invalid_argument);
}

}  // namespace
}  // namespace arco
