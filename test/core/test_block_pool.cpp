// BlockPool: every block runs once, whatever the thread count; the results, written per block,
// are the same on 1 to 4 threads; an exception in a block comes out of run() after the rest;
// a pool survives many loops back to back (helpers waking late find no stale loop).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <numeric>
#include <stdexcept>
#include <thread>
#include <vector>

#include "cvo_odometry/core/block_pool.hpp"

namespace cvo {
namespace {

TEST(BlockPool, EveryBlockRunsExactlyOnceOnAnyThreadCount) {
  for (int threads = 1; threads <= 4; ++threads) {
    BlockPool pool(threads);
    EXPECT_EQ(pool.threads(), threads);
    for (std::size_t count : {0u, 1u, 2u, 7u, 1000u}) {
      std::vector<std::atomic<int>> runs(count);
      pool.run(count, [&](std::size_t b) { ++runs[b]; });
      for (std::size_t b = 0; b < count; ++b)
        ASSERT_EQ(runs[b].load(), 1) << threads << " threads, block " << b << " of " << count;
    }
  }
}

// A pool limited to fewer threads than it has: every block once, on no more distinct threads
// than the limit (one: the caller alone), and all threads again when the limit is lifted.
TEST(BlockPool, ActiveThreadsLimitWhoRunsTheBlocks) {
  BlockPool pool(3);
  EXPECT_EQ(pool.activeThreads(), 3);
  pool.setActiveThreads(0);
  EXPECT_EQ(pool.activeThreads(), 1);
  pool.setActiveThreads(7);
  EXPECT_EQ(pool.activeThreads(), 3);
  for (int active : {1, 2, 3}) {
    pool.setActiveThreads(active);
    for (int loop = 0; loop < 50; ++loop) {
      constexpr std::size_t kCount = 64;
      std::vector<std::atomic<int>> runs(kCount);
      std::vector<std::thread::id> ran_on(kCount);
      pool.run(kCount, [&](std::size_t b) {
        ++runs[b];
        ran_on[b] = std::this_thread::get_id();
        // Long enough for the helpers to wake and claim their shares.
        std::this_thread::sleep_for(std::chrono::microseconds(20));
      });
      std::vector<std::thread::id> threads(ran_on);
      std::sort(threads.begin(), threads.end());
      threads.erase(std::unique(threads.begin(), threads.end()), threads.end());
      for (std::size_t b = 0; b < kCount; ++b)
        ASSERT_EQ(runs[b].load(), 1) << active << " active, block " << b;
      ASSERT_LE(static_cast<int>(threads.size()), active);
      if (active == 1) {
        ASSERT_EQ(threads.front(), std::this_thread::get_id());
      }
    }
  }
}

TEST(BlockPool, ManyShortLoopsBackToBack) {
  BlockPool pool(3);
  std::vector<double> partial(16);
  double total = 0.0;
  for (int loop = 0; loop < 5000; ++loop) {
    pool.run(partial.size(), [&](std::size_t b) { partial[b] = loop + 0.001 * b; });
    total += std::accumulate(partial.begin(), partial.end(), 0.0);
  }
  double expected = 0.0;
  for (int loop = 0; loop < 5000; ++loop) {
    std::vector<double> serial(partial.size());
    for (std::size_t b = 0; b < serial.size(); ++b)
      serial[b] = loop + 0.001 * b;
    expected += std::accumulate(serial.begin(), serial.end(), 0.0);
  }
  EXPECT_EQ(total, expected);  // same additions in the same order
}

TEST(BlockPool, TheCallerFinishesTheShareOfAHelperHeldUpInABlock) {
  // A helper holds the first block it gets until every other block has run, as a descheduled
  // one would: the caller must take the rest of that helper's share (else run() never returns).
  BlockPool pool(2);
  const std::thread::id caller = std::this_thread::get_id();
  int loops_held = 0;
  for (int loop = 0; loop < 200; ++loop) {
    constexpr std::size_t kCount = 64;
    std::atomic<std::size_t> finished{0};
    std::atomic<bool> held{false};
    pool.run(kCount, [&](std::size_t) {
      volatile double work = 0.0;  // long enough for the helper to wake and claim a block
      for (int i = 0; i < 2000; ++i)
        work = work + i;
      if (std::this_thread::get_id() != caller && !held.exchange(true)) {
        while (finished.load() + 1 < kCount)
          std::this_thread::yield();
      }
      ++finished;
    });
    ASSERT_EQ(finished.load(), kCount);
    loops_held += held.load() ? 1 : 0;
  }
  RecordProperty("loops_with_a_held_helper", loops_held);
}

TEST(BlockPool, AnExceptionComesOutAfterTheOtherBlocks) {
  BlockPool pool(2);
  std::atomic<int> finished{0};
  EXPECT_THROW(pool.run(50,
                        [&](std::size_t b) {
                          if (b == 10) throw std::runtime_error("block 10");
                          ++finished;
                        }),
               std::runtime_error);
  EXPECT_EQ(finished.load(), 49);
  // The pool still works.
  std::atomic<int> again{0};
  pool.run(20, [&](std::size_t) { ++again; });
  EXPECT_EQ(again.load(), 20);
}

}  // namespace
}  // namespace cvo
