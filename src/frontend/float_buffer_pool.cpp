#include "cvo_odometry/frontend/float_buffer_pool.hpp"

#include <utility>

namespace cvo {

FloatBufferPool::FloatBufferPool(std::size_t max_kept) : max_kept_(max_kept) {
  kept_.reserve(max_kept_);  // give() then never allocates
}

std::vector<float> FloatBufferPool::take(std::size_t size) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto it = kept_.begin(); it != kept_.end(); ++it) {
      if (it->size() == size) {
        std::vector<float> buffer = std::move(*it);
        kept_.erase(it);
        return buffer;
      }
    }
  }
  return std::vector<float>(size);
}

void FloatBufferPool::give(std::vector<float> buffer) noexcept {
  if (buffer.empty()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (max_kept_ == 0) return;
  // Full: the buffer kept longest goes (so after the images change size the new size takes
  // over); the capacity reserved up front means no allocation here.
  if (kept_.size() == max_kept_) kept_.erase(kept_.begin());
  kept_.push_back(std::move(buffer));
}

std::size_t FloatBufferPool::kept() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return kept_.size();
}

}  // namespace cvo
