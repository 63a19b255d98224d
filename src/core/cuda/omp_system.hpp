// The OpenMP system of the device code (the device_cpu backend): Thrust's algorithms on host
// threads, device vectors in host memory. One addition: the reduction. Thrust's own OpenMP reduce
// splits a range by the processor count, so its float sums would differ from machine to machine;
// here every thrust::reduce / transform_reduce called with ChunkedReducePolicy (found by
// argument-dependent lookup) folds fixed chunks of kReduceChunk items in order and adds the chunk
// sums in chunk order: the same bits for any thread or processor count, run to run.
#pragma once

#include <omp.h>
#include <thrust/system/omp/execution_policy.h>

#include <algorithm>
#include <cstddef>
#include <vector>

#include "cvo_odometry/core/device_pair_sums.hpp"

namespace cvo {
namespace device {

constexpr DeviceSystem kSystem = DeviceSystem::kOmp;
constexpr const char* kSystemName = "device_cpu";

constexpr long kReduceChunk = 64;  // (source point, lane) items a chunk

struct ChunkedReducePolicy : thrust::system::omp::execution_policy<ChunkedReducePolicy> {
  int threads = 1;
};

template <class Iterator, class T, class BinaryOp>
T reduce(ChunkedReducePolicy& policy, Iterator first, Iterator last, T init, BinaryOp op) {
  const long n = static_cast<long>(last - first);
  const long chunks = (n + kReduceChunk - 1) / kReduceChunk;
  std::vector<T> partial(static_cast<std::size_t>(chunks));
#pragma omp parallel for schedule(dynamic, 1) num_threads(policy.threads)
  for (long c = 0; c < chunks; ++c) {
    const long end = std::min(n, (c + 1) * kReduceChunk);
    T sum = first[c * kReduceChunk];
    for (long k = c * kReduceChunk + 1; k < end; ++k)
      sum = op(sum, first[k]);
    partial[static_cast<std::size_t>(c)] = sum;
  }
  for (const T& sum : partial)
    init = op(init, sum);
  return init;
}

// What the shared source asks of a system: its execution policy and uploads.
class Runtime {
 public:
  explicit Runtime(int threads) { policy_.threads = threads > 0 ? threads : omp_get_max_threads(); }
  ChunkedReducePolicy& policy() { return policy_; }
  // Copies `arrays` host arrays of sizes[a] floats to device[a].
  void upload(int arrays, const float* const* host, const std::size_t* sizes,
              float* const* device) {
    for (int a = 0; a < arrays; ++a)
      std::copy(host[a], host[a] + sizes[a], device[a]);
  }

 private:
  ChunkedReducePolicy policy_;
};

}  // namespace device
}  // namespace cvo
