// Float buffers handed back by the images that used them, for the next frame's images. A frame's
// photometric levels are 1.2 MB each at 640x480; allocated anew every frame, each cost a zero
// fill and hundreds of first-touch page faults (about 9 us each on the VMs we measure on), on the
// thread that runs the frame. Thread-safe: an image may be released on another thread.
#pragma once

#include <cstddef>
#include <mutex>
#include <vector>

namespace cvo {

class FloatBufferPool {
 public:
  // Keeps at most `max_kept` handed-back buffers.
  explicit FloatBufferPool(std::size_t max_kept);

  // A buffer of `size` floats: a kept one of that size when there is one (its values are what
  // its last user left), else a new one (zeros).
  std::vector<float> take(std::size_t size);
  // Keeps `buffer` for a later take(), in place of the buffer kept longest when max_kept are
  // kept (after the images change size, the new size takes over). Allocates nothing (it runs in
  // an image's deleter); a mutex that fails to lock terminates.
  void give(std::vector<float> buffer) noexcept;

  std::size_t kept() const;

 private:
  mutable std::mutex mutex_;
  std::size_t max_kept_;
  std::vector<std::vector<float>> kept_;
};

}  // namespace cvo
