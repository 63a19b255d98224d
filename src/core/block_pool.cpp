#include "cvo_odometry/core/block_pool.hpp"

#include <chrono>
#include <exception>

namespace cvo {

struct BlockPool::Loop {
  std::size_t count = 0;
  const std::function<void(std::size_t)>* block = nullptr;  // valid while blocks remain
  std::atomic<std::size_t> next{0};                         // the next block to claim
  std::atomic<std::size_t> done{0};                         // blocks finished
  std::mutex mutex;                                         // guards error, signals the end
  std::condition_variable finished;
  std::exception_ptr error;
};

BlockPool::BlockPool(int threads) {
  for (int k = 1; k < threads; ++k)
    helpers_.emplace_back([this] { help(); });
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

void BlockPool::work(Loop& loop) {
  for (;;) {
    const std::size_t b = loop.next.fetch_add(1);
    if (b >= loop.count) return;  // `block` may be gone from here on: not touched again
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
}

void BlockPool::help() {
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
    if (loop) work(*loop);
  }
}

void BlockPool::run(std::size_t count, const std::function<void(std::size_t)>& block) {
  if (count == 0) return;
  std::lock_guard<std::mutex> serial(run_mutex_);
  auto loop = std::make_shared<Loop>();
  loop->count = count;
  loop->block = &block;
  if (!helpers_.empty() && count > 1) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      loop_ = loop;
      started_.store(++generation_);
    }
    wake_.notify_all();
  }
  work(*loop);
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
