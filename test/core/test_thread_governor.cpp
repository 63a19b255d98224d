// ThreadGovernor: all threads while the frames get more than min_cores; one thread for a pause
// once the median of a window falls below it; a try that finds no more cores doubles the pause
// (up to max_pause), one that finds them ends the fallback; one thread means nothing to decide.
#include <gtest/gtest.h>

#include <stdexcept>

#include "cvo_odometry/core/thread_governor.hpp"

namespace cvo {
namespace {

ThreadGovernorOptions options() {
  ThreadGovernorOptions o;
  o.window = 3;
  o.min_cores = 1.15;
  o.first_pause = 4;
  o.max_pause = 10;
  return o;
}

// Feeds `frames` frames of `cores` cores (20 ms each); returns how many ran on one thread.
int feed(ThreadGovernor& governor, double cores, int frames) {
  int one = 0;
  for (int k = 0; k < frames; ++k) {
    if (governor.threads() == 1) ++one;
    governor.update(20.0, 20.0 * cores);
  }
  return one;
}

TEST(ThreadGovernor, IdleFramesKeepEveryThreadAndOneOddFrameChangesNothing) {
  ThreadGovernor governor(2, options());
  EXPECT_EQ(feed(governor, 1.6, 10), 0);
  governor.update(20.0, 20.0 * 0.7);  // one frame with less parallel work: the median holds
  EXPECT_EQ(feed(governor, 1.6, 10), 0);
  EXPECT_EQ(governor.fallbacks(), 0);
}

TEST(ThreadGovernor, LoadedFramesFallBackThenTriesBackOffAndRecover) {
  ThreadGovernor governor(2, options());
  EXPECT_EQ(feed(governor, 0.6, 3), 0);  // the window fills: judged after its third frame
  EXPECT_EQ(governor.threads(), 1);
  EXPECT_EQ(governor.fallbacks(), 1);
  EXPECT_EQ(feed(governor, 0.6, 4), 4);  // the first pause
  EXPECT_EQ(governor.threads(), 2);      // a try
  EXPECT_EQ(feed(governor, 0.6, 3), 0);  // which finds no more cores
  EXPECT_EQ(governor.threads(), 1);
  EXPECT_EQ(feed(governor, 0.6, 8), 8);  // the pause doubled
  EXPECT_EQ(governor.threads(), 2);
  feed(governor, 0.6, 3);
  EXPECT_EQ(feed(governor, 0.6, 10), 10);  // doubled again, up to max_pause
  EXPECT_EQ(governor.threads(), 2);
  EXPECT_EQ(governor.reducedFrames(), 22);
  // The load is gone: the try keeps all threads, and the next fallback starts short again.
  EXPECT_EQ(feed(governor, 1.6, 10), 0);
  feed(governor, 0.6, 2);  // the window's median turns with its second low frame
  EXPECT_EQ(governor.threads(), 1);
  EXPECT_EQ(feed(governor, 0.6, 4), 4);
  EXPECT_EQ(governor.threads(), 2);
}

TEST(ThreadGovernor, NothingToDecideOrMeasure) {
  ThreadGovernor one(1, options());
  EXPECT_EQ(feed(one, 0.3, 20), 20);
  EXPECT_EQ(one.fallbacks(), 0);
  ThreadGovernor governor(4, options());
  for (int k = 0; k < 10; ++k)
    governor.update(0.5, 0.0);  // too short to measure: not judged
  governor.update(20.0, -1.0);  // a clock that went backwards: not judged
  EXPECT_EQ(governor.threads(), 4);
  ThreadGovernorOptions bad = options();
  bad.max_pause = 2;
  EXPECT_THROW(ThreadGovernor(2, bad), std::invalid_argument);
  bad = options();
  bad.window = 0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace cvo
