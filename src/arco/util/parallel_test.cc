#include "arco/util/parallel.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <thread>

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

TEST(ParallelFor, RethrowsAWorkerExceptionOnTheCallingThread) {
  for (int threads : {1, 2, 4}) {
    std::atomic<int64_t> calls{0};
    try {
      ParallelFor(10000, threads, [&](int64_t i, int) {
        ++calls;
        if (i == 137) throw std::runtime_error("item 137 failed");
      }, 4);
      ADD_FAILURE() << "no exception with " << threads << " threads";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "item 137 failed");
    }
    // Workers stop taking items after the failure: far fewer than all 10000 ran.
    EXPECT_LT(calls.load(), 10000) << threads << " threads";
  }
}

TEST(ParallelFor, RethrowsTheLowestFailingItem) {
  // Items 40 and 48 fail. With several threads, item 40 (first of its chunk) waits
  // until item 48 (on another thread) has failed, so 48's exception is caught first;
  // the one rethrown is still item 40's, as in a plain loop.
  for (int threads : {1, 2, 3}) {
    std::atomic<bool> item48_failed{false};
    try {
      ParallelFor(1000, threads, [&](int64_t i, int) {
        if (i == 48) {
          item48_failed = true;
          throw std::out_of_range("48");
        }
        if (i == 40) {
          const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
          while (threads > 1 && !item48_failed && std::chrono::steady_clock::now() < give_up) {
            std::this_thread::yield();
          }
          throw std::out_of_range("40");
        }
      }, 8);
      ADD_FAILURE() << "no exception";
    } catch (const std::out_of_range& e) {
      EXPECT_STREQ(e.what(), "40") << threads << " threads";
    }
  }
}

TEST(ParallelFor, FinishesRunningItemsBeforeRethrowing) {
  // Items writing their slots are not cut off mid-way: every item that started
  // also finished by the time the exception reaches the caller.
  std::vector<std::atomic<int>> state(4000);
  EXPECT_THROW(ParallelFor(4000, 4, [&](int64_t i, int) {
                 state[i] = 1;  // started
                 if (i == 2001) throw std::logic_error("fail");
                 state[i] = 2;  // finished
               }, 1),
               std::logic_error);
  for (int64_t i = 0; i < 4000; ++i) {
    if (i != 2001) {
      EXPECT_NE(state[i].load(), 1) << "item " << i << " left half done";
    }
  }
}

}  // namespace
}  // namespace arco
