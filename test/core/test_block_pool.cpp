// BlockPool: every block runs once, whatever the thread count; the results, written per block,
// are the same on 1 to 4 threads; an exception in a block comes out of run() after the rest;
// a pool survives many loops back to back (helpers waking late find no stale loop).
#include <gtest/gtest.h>

#include <atomic>
#include <numeric>
#include <stdexcept>
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
