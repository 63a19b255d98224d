// Runs the blocks of a loop on the calling thread and a few helper threads, for the CPU
// backend's per-block sums. Unlike an OpenMP parallel region, the end of a loop waits only for
// blocks a helper has started, never for a helper that has not been scheduled yet: the caller
// claims blocks too, so on cores shared with other processes (a robot's normal state) a
// descheduled helper costs nothing instead of a time slice at every barrier. Measured before
// this existed: 2 OpenMP threads under two busy loops took 2x the time of 1 thread (README
// "Benchmark"). Each thread starts on its own contiguous share of the blocks, the same share
// every loop of the same size, and takes the rest of another's once its own is done: a block's
// data (the CPU backend's candidate lists, built in one loop and summed in the next) usually
// stays in the cache of the core that wrote it (threads are not pinned). Which thread runs a block
// does not matter to the results: callers write one result per block and combine them in block
// order.
#pragma once

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace cvo {

class BlockPool {
 public:
  // `threads` in all, the caller included (1: no helper thread).
  explicit BlockPool(int threads);
  ~BlockPool();
  BlockPool(const BlockPool&) = delete;
  BlockPool& operator=(const BlockPool&) = delete;

  int threads() const { return static_cast<int>(helpers_.size()) + 1; }

  // Loops from the next one on share their blocks among at most `threads` of the pool's threads
  // (the caller counts; clamped to [1, threads()]): fewer while the helpers get no core of their
  // own (ThreadGovernor). The results do not change.
  void setActiveThreads(int threads);
  int activeThreads() const { return active_.load(); }

  // Calls block(b) once for every b in [0, count) and returns when all have returned; the
  // first exception a block throws is rethrown here, after the others finished. One loop at a
  // time per pool (callers serialize).
  void run(std::size_t count, const std::function<void(std::size_t)>& block);

 private:
  struct Loop;
  // Helper `self` (1, 2, ...; the caller is 0) waiting for loops and working on them.
  void help(int self);
  // Claims and runs blocks of `loop` until none is left: thread `self`'s share first, from its
  // front, then the others' from their backs.
  static void work(Loop& loop, int self);
  // run() for at most 2^32 - 1 blocks (a share's range is two 32-bit halves).
  void runLoop(std::size_t count, const std::function<void(std::size_t)>& block);
  static void runBlock(Loop& loop, std::size_t b);

  std::mutex run_mutex_;  // one loop at a time
  std::mutex mutex_;
  std::condition_variable wake_;
  std::shared_ptr<Loop> loop_;           // the current loop, null between loops
  std::size_t generation_ = 0;           // loops started
  std::atomic<std::size_t> started_{0};  // generation_, read without the lock
  bool stop_ = false;
  std::vector<std::thread> helpers_;
  std::atomic<int> active_{1};  // threads a loop shares its blocks among
};

// Calls block(b) for every b in [0, count) on `pool`, or on this thread alone, in order, when
// `pool` is null.
template <class Block>
void forEachBlock(BlockPool* pool, std::size_t count, Block&& block) {
  if (pool == nullptr) {
    for (std::size_t b = 0; b < count; ++b)
      block(b);
    return;
  }
  pool->run(count, block);
}

// Calls item(i) for every i in [0, n), in blocks of `block_size` items (forEachBlock).
template <class Item>
void forEachInBlocks(BlockPool* pool, std::size_t n, std::size_t block_size, Item&& item) {
  forEachBlock(pool, (n + block_size - 1) / block_size, [&](std::size_t b) {
    const std::size_t end = std::min(n, (b + 1) * block_size);
    for (std::size_t i = b * block_size; i < end; ++i)
      item(i);
  });
}

}  // namespace cvo
