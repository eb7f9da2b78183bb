#include "arco/util/parallel.h"

#include <cmath>
#include <numeric>

#include <gtest/gtest.h>

namespace arco {
namespace {

TEST(ParallelFor, SameResultForAnyThreadCount) {
  std::vector<double> one(1000), many(1000);
  auto work = [](int64_t i) { return std::sin(static_cast<double>(i)) * i; };
  ParallelFor(1000, 1, [&](int64_t i, int) { one[i] = work(i); });
  ParallelFor(1000, 4, [&](int64_t i, int) { many[i] = work(i); }, 7);
  EXPECT_EQ(one, many);
}

TEST(ParallelFor, HandlesEmptyRange) {
  int calls = 0;
  ParallelFor(0, 4, [&](int64_t, int) { ++calls; });
  EXPECT_EQ(calls, 0);
}

}  // namespace
}  // namespace arco
