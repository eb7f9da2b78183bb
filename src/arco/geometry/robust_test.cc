#include "arco/geometry/robust.h"

#include <gtest/gtest.h>

#include <set>
#include <stdexcept>

namespace arco {
namespace {

TEST(SplitMix64, SequenceIsFixed) {
  // Reference values of SplitMix64 seeded with 0 (Vigna's reference implementation).
  SplitMix64 rng(0);
  EXPECT_EQ(rng.Next(), 0xE220A8397B1DCDAFull);
  EXPECT_EQ(rng.Next(), 0x6E789E6AA1B965F4ull);
}

TEST(RansacTrialsNeeded, MatchesFormula) {
  EXPECT_EQ(RansacTrialsNeeded(1.0, 2, 0.99), 1);
  // log(0.01) / log(1 - 0.25) = 16.008 -> 17.
  EXPECT_EQ(RansacTrialsNeeded(0.5, 2, 0.99), 17);
  EXPECT_GE(RansacTrialsNeeded(0.0, 2, 0.99), 1000000);
}

TEST(MakePairSchedule, FewViewsGivesEveryPairBestFirst) {
  const auto pairs = MakePairSchedule(4, 64, 1);
  ASSERT_EQ(pairs.size(), 6u);
  EXPECT_EQ(pairs[0], std::make_pair(0, 1));
  EXPECT_EQ(pairs[1], std::make_pair(0, 2));
  std::set<std::pair<int, int>> unique(pairs.begin(), pairs.end());
  EXPECT_EQ(unique.size(), 6u);
}

TEST(MakePairSchedule, ManyViewsIsBoundedDistinctAndCoversViews) {
  const int n = 24;
  const auto pairs = MakePairSchedule(n, 40, 7);
  ASSERT_EQ(pairs.size(), 40u);
  EXPECT_EQ(pairs[0], std::make_pair(0, 1));
  std::set<std::pair<int, int>> unique;
  std::set<int> views;
  for (auto [i, j] : pairs) {
    EXPECT_LT(i, j);
    EXPECT_GE(i, 0);
    EXPECT_LT(j, n);
    unique.insert({i, j});
    views.insert(i);
    views.insert(j);
  }
  EXPECT_EQ(unique.size(), pairs.size());
  EXPECT_GT(views.size(), 15u);                  // the random part reaches low-confidence views too
  EXPECT_EQ(pairs, MakePairSchedule(n, 40, 7));  // deterministic
}

TEST(MakePairSchedule, RejectsBadArguments) {
  EXPECT_THROW(MakePairSchedule(-1, 10, 0), std::invalid_argument);
  EXPECT_THROW(MakePairSchedule(5, 0, 0), std::invalid_argument);
}

}  // namespace
}  // namespace arco
