// Frames handed from the subscriber callbacks to the nodelet's worker thread. Live (keep_all
// false) it holds only the newest frame: one that arrives while another waits replaces it, and
// the replaced one is counted as dropped, so latency stays bounded by one frame's processing
// whatever the load. For bag replay (keep_all true) every frame waits its turn, in order.
// A frame pushed with `keep` (the first frames of a start, which waited for the synchronizer's
// stamp offset and come together) is never replaced: it waits its turn like a replayed frame.
#pragma once

#include <algorithm>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>

namespace cvo {

template <class Frame>
class FrameQueue {
 public:
  explicit FrameQueue(bool keep_all) : keep_all_(keep_all) {}

  void push(Frame frame, bool keep = false) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!keep_all_) {
        const auto replaced = std::remove_if(frames_.begin(), frames_.end(),
                                             [](const Waiting& waiting) { return !waiting.keep; });
        dropped_ += static_cast<std::size_t>(frames_.end() - replaced);
        frames_.erase(replaced, frames_.end());
      }
      frames_.push_back({std::move(frame), keep});
    }
    ready_.notify_one();
  }

  // The next frame, waiting for one; nothing once close() was called.
  std::optional<Frame> pop() {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait(lock, [this] { return closed_ || !frames_.empty(); });
    if (closed_) return std::nullopt;
    Frame frame = std::move(frames_.front().frame);
    frames_.pop_front();
    return frame;
  }

  // Frames waiting are dropped (counted); pop() returns nothing from now on.
  void close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    ready_.notify_all();
  }

  // Frames waiting now (to clear them on a reset: they belong to the old trajectory).
  void clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    frames_.clear();
  }

  std::size_t dropped() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return dropped_;
  }
  std::size_t waiting() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return frames_.size();
  }

 private:
  struct Waiting {
    Frame frame;
    bool keep;
  };

  const bool keep_all_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<Waiting> frames_;
  std::size_t dropped_ = 0;
  bool closed_ = false;
};

}  // namespace cvo
