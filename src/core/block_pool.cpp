#include "cvo_odometry/core/block_pool.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <exception>

namespace cvo {

struct BlockPool::Loop {
  std::size_t count = 0;
  const std::function<void(std::size_t)>* block = nullptr;  // valid while blocks remain
  // Each thread's share of the blocks, a contiguous range [front, back) packed in one word
  // (front in the high half): its owner claims from the front, a thread done with its own share
  // takes from the back of another's. The same block count is shared the same way every loop,
  // so a block usually runs on the thread that ran it last (its data in that core's cache,
  // while the scheduler keeps the thread there) unless the threads fall out of step.
  // A cache line each: one thread's claims do not invalidate the line another steals from.
  struct alignas(64) Share {
    std::atomic<std::uint64_t> range{0};
  };
  int shares = 1;
  std::unique_ptr<Share[]> ranges;
  std::atomic<std::size_t> done{0};  // blocks finished
  std::mutex mutex;                  // guards error, signals the end
  std::condition_variable finished;
  std::exception_ptr error;
};

namespace {

constexpr std::uint64_t kHalf = 0xffffffffu;

std::uint64_t packRange(std::uint64_t front, std::uint64_t back) {
  return front << 32 | back;
}

// Claims the front (or back) block of `range`; false when it is empty.
bool claim(std::atomic<std::uint64_t>& range, bool from_front, std::size_t* block) {
  std::uint64_t value = range.load();
  for (;;) {
    const std::uint64_t front = value >> 32, back = value & kHalf;
    if (front >= back) return false;
    const std::uint64_t next = from_front ? packRange(front + 1, back) : packRange(front, back - 1);
    if (range.compare_exchange_weak(value, next)) {
      *block = static_cast<std::size_t>(from_front ? front : back - 1);
      return true;
    }
  }
}

}  // namespace

BlockPool::BlockPool(int threads) {
  for (int k = 1; k < threads; ++k)
    helpers_.emplace_back([this, k] { help(k); });
  active_.store(this->threads());
}

void BlockPool::setActiveThreads(int threads) {
  active_.store(std::clamp(threads, 1, this->threads()));
}

BlockPool::~BlockPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (auto& helper : helpers_)
    helper.join();
}

void BlockPool::runBlock(Loop& loop, std::size_t b) {
  try {
    (*loop.block)(b);
  } catch (...) {
    std::lock_guard<std::mutex> lock(loop.mutex);
    if (!loop.error) loop.error = std::current_exception();
  }
  if (loop.done.fetch_add(1) + 1 == loop.count) {
    std::lock_guard<std::mutex> lock(loop.mutex);
    loop.finished.notify_all();
  }
}

void BlockPool::work(Loop& loop, int self) {
  // self < loop.shares: a loop of one share is never published to the helpers, and a published
  // one has a share for every active thread (help() leaves the others out). Once no range holds a
  // block, `block` may be gone: it is not touched again.
  std::size_t b = 0;
  while (claim(loop.ranges[self].range, true, &b))
    runBlock(loop, b);
  for (int k = 1; k < loop.shares; ++k) {
    while (claim(loop.ranges[(self + k) % loop.shares].range, false, &b))
      runBlock(loop, b);
  }
}

void BlockPool::help(int self) {
  std::size_t seen = 0;
  for (;;) {
    // Loops come back to back within a registration: look for the next one a little while
    // (yielding, so a shared core goes to whoever needs it) before sleeping.
    const auto spin_until = std::chrono::steady_clock::now() + std::chrono::microseconds(100);
    while (started_.load() == seen && std::chrono::steady_clock::now() < spin_until)
      std::this_thread::yield();
    std::shared_ptr<Loop> loop;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      loop = loop_;
    }
    // A loop shared among fewer threads than the pool has leaves the others out.
    if (loop && self < loop->shares) work(*loop, self);
  }
}

void BlockPool::run(std::size_t count, const std::function<void(std::size_t)>& block) {
  if (count <= kHalf) {
    runLoop(count, block);
    return;
  }
  // More blocks than a range's half word holds (never in practice): loops of at most that many,
  // each finished, the first exception rethrown at the end.
  std::exception_ptr error;
  for (std::size_t first = 0; first < count; first += kHalf) {
    const std::function<void(std::size_t)> part = [&](std::size_t b) { block(first + b); };
    try {
      runLoop(std::min<std::size_t>(kHalf, count - first), part);
    } catch (...) {
      if (!error) error = std::current_exception();
    }
  }
  if (error) std::rethrow_exception(error);
}

void BlockPool::runLoop(std::size_t count, const std::function<void(std::size_t)>& block) {
  if (count == 0) return;
  std::lock_guard<std::mutex> serial(run_mutex_);
  auto loop = std::make_shared<Loop>();
  loop->count = count;
  loop->block = &block;
  const int active = active_.load();
  const bool shared = active > 1 && count > 1;
  loop->shares = shared ? active : 1;
  loop->ranges = std::make_unique<Loop::Share[]>(static_cast<std::size_t>(loop->shares));
  const std::uint64_t n = count, shares = static_cast<std::uint64_t>(loop->shares);
  for (std::uint64_t k = 0; k < shares; ++k)
    loop->ranges[k].range.store(packRange(n * k / shares, n * (k + 1) / shares));
  if (shared) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      loop_ = loop;
      started_.store(++generation_);
    }
    wake_.notify_all();
  }
  work(*loop, 0);
  // Only blocks a helper has claimed can still be running: wait for those, briefly spinning
  // (they are short), then asleep.
  const auto spin_until = std::chrono::steady_clock::now() + std::chrono::microseconds(50);
  while (loop->done.load() != count && std::chrono::steady_clock::now() < spin_until) {
  }
  {
    std::unique_lock<std::mutex> lock(loop->mutex);
    loop->finished.wait(lock, [&] { return loop->done.load() == count; });
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    loop_.reset();  // a helper waking late finds no loop; one that took it finds no block left
  }
  if (loop->error) std::rethrow_exception(loop->error);
}

}  // namespace cvo
