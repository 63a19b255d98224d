// The CUDA system of the device code (the `cuda` backend): a stream, pinned staging for uploads,
// a caching allocator for Thrust's temporary storage, CUDA errors as exceptions. Everything else
// is the shared Thrust source (device_pair_sums.cu).
#pragma once

#include <cuda_runtime.h>
#include <thrust/system/cuda/execution_policy.h>

#include <cstddef>
#include <map>

#include "cvo_odometry/core/device_pair_sums.hpp"

namespace cvo {
namespace device {

constexpr DeviceSystem kSystem = DeviceSystem::kCuda;
constexpr const char* kSystemName = "CUDA";

// Throws std::runtime_error naming `what` when status is an error.
void check(cudaError_t status, const char* what);

// Thrust's temporary storage (sort, reduce): a freed block is kept and handed out again (the
// smallest that fits), so that once the sizes have been seen an evaluation allocates no device
// memory. All use is on one stream: a block freed by one algorithm may serve the next at once.
class CachingAllocator {
 public:
  using value_type = char;
  CachingAllocator() = default;
  CachingAllocator(const CachingAllocator&) = delete;
  CachingAllocator& operator=(const CachingAllocator&) = delete;
  ~CachingAllocator();
  char* allocate(std::ptrdiff_t bytes);
  void deallocate(char* block, std::size_t bytes);

 private:
  std::multimap<std::ptrdiff_t, char*> free_;
  std::map<char*, std::ptrdiff_t> in_use_;
};

// What the shared source asks of a system: its execution policy and uploads.
class Runtime {
 public:
  explicit Runtime(int threads);  // `threads`: unused
  ~Runtime();
  Runtime(const Runtime&) = delete;
  Runtime& operator=(const Runtime&) = delete;

  // The algorithms on the stream, temporaries from the cache, no wait after each algorithm: an
  // evaluation waits once, for its result.
  auto policy() { return thrust::cuda::par_nosync(allocator_).on(stream_); }
  // Copies `arrays` host arrays of sizes[a] floats to device[a] through pinned memory; waits.
  void upload(int arrays, const float* const* host, const std::size_t* sizes, float* const* device);

 private:
  // A blocking stream: device vectors grow on the legacy default stream, ordered with it.
  cudaStream_t stream_ = nullptr;
  CachingAllocator allocator_;
  float* pinned_ = nullptr;
  std::size_t pinned_capacity_ = 0;
};

}  // namespace device
}  // namespace cvo
