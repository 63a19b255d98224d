#include "cuda_system.cuh"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace cvo {
namespace device {

void check(cudaError_t status, const char* what) {
  if (status != cudaSuccess) {
    throw std::runtime_error(std::string("CUDA ") + what + ": " + cudaGetErrorString(status));
  }
}

CachingAllocator::~CachingAllocator() {
  for (const auto& block : free_)
    cudaFree(block.second);
  for (const auto& block : in_use_)
    cudaFree(block.first);
}

char* CachingAllocator::allocate(std::ptrdiff_t bytes) {
  char* block = nullptr;
  const auto fit = free_.lower_bound(bytes);
  if (fit != free_.end()) {
    bytes = fit->first;
    block = fit->second;
    free_.erase(fit);
  } else if (cudaMalloc(&block, std::max<std::ptrdiff_t>(bytes, 1)) != cudaSuccess) {
    cudaGetLastError();
    for (const auto& cached : free_)  // give the cache back and try once more
      cudaFree(cached.second);
    free_.clear();
    check(cudaMalloc(&block, std::max<std::ptrdiff_t>(bytes, 1)), "cudaMalloc (temporary storage)");
  }
  in_use_.emplace(block, bytes);
  return block;
}

void CachingAllocator::deallocate(char* block, std::size_t) {
  const auto used = in_use_.find(block);
  if (used == in_use_.end()) return;
  free_.emplace(used->second, block);
  in_use_.erase(used);
}

Runtime::Runtime(int) {
  check(cudaStreamCreate(&stream_), "cudaStreamCreate");
}

Runtime::~Runtime() {
  if (pinned_) cudaFreeHost(pinned_);
  if (stream_) cudaStreamDestroy(stream_);
}

void Runtime::upload(int arrays, const float* const* host, const std::size_t* sizes,
                     float* const* device) {
  std::size_t total = 0;
  for (int a = 0; a < arrays; ++a)
    total += sizes[a];
  if (total > pinned_capacity_) {
    if (pinned_) cudaFreeHost(pinned_);
    pinned_ = nullptr;
    pinned_capacity_ = 0;  // a failed allocation leaves no stale size
    check(cudaMallocHost(&pinned_, total * sizeof(float)), "cudaMallocHost");
    pinned_capacity_ = total;
  }
  std::size_t offset = 0;
  for (int a = 0; a < arrays; ++a) {
    if (sizes[a] == 0) continue;
    std::copy(host[a], host[a] + sizes[a], pinned_ + offset);
    check(cudaMemcpyAsync(device[a], pinned_ + offset, sizes[a] * sizeof(float),
                          cudaMemcpyHostToDevice, stream_),
          "upload");
    offset += sizes[a];
  }
  check(cudaStreamSynchronize(stream_), "upload");  // the staging buffer is reused
}

}  // namespace device

bool cudaDeviceUsable(std::string* why_not) {
  int devices = 0;
  const cudaError_t status = cudaGetDeviceCount(&devices);
  if (status != cudaSuccess || devices == 0) {
    if (why_not) {
      *why_not = status != cudaSuccess
                     ? std::string("no CUDA device: ") + cudaGetErrorString(status)
                     : "no CUDA device found";
    }
    cudaGetLastError();  // clear the sticky error of a failed query
    return false;
  }
  return true;
}

}  // namespace cvo
