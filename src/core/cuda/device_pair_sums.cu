#include <cuda_runtime.h>

#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "cvo_odometry/core/dense_grid.hpp"
#include "cvo_odometry/core/device_pair_sums.hpp"

namespace cvo {

namespace {

constexpr int kThreads = 128;  // one source point a thread, one partial sum a block

void check(cudaError_t status, const char* what) {
  if (status != cudaSuccess) {
    throw std::runtime_error(std::string("CUDA ") + what + ": " + cudaGetErrorString(status));
  }
}

// A device array that only grows.
template <class T>
struct DeviceBuffer {
  T* data = nullptr;
  std::size_t capacity = 0;
  void reserve(std::size_t n) {
    if (n <= capacity) return;
    if (data) cudaFree(data);
    data = nullptr;
    capacity = 0;  // a failed allocation leaves an empty buffer, not a stale size
    check(cudaMalloc(&data, std::max<std::size_t>(n, 1) * sizeof(T)), "cudaMalloc");
    capacity = n;
  }
  ~DeviceBuffer() {
    if (data) cudaFree(data);
  }
};

// The pose and twist travel as kernel arguments: no copy, no host wait per evaluation.
struct Pose3x4 {
  float m[12];
};
struct Twist {
  double v[6];
};

struct GridView {
  kernels::DenseGridShape shape;
  const unsigned int* start;  // cells + 1 offsets into the sorted target arrays
  float radius;               // the query radius (<= the cell edge)
};

struct CloudView {
  const float* positions;
  const float* colors;
  const float* semantics;
  int count;
};

// What one evaluation's kernel needs, copied into its device lambda.
struct Evaluation {
  int blocks;
  Pose3x4 pose;
  CloudView target, source;
  GridView grid;
  kernels::KernelConstants k;
  float inv_two_ell2;
  double inv_ell2;
};

// Visits the target points in the cell ranges the query ball around z reaches.
template <class F>
__device__ void forEachCandidate(const GridView& grid, const float* z, F&& f) {
  kernels::forEachRangeWithin(grid.shape, grid.start, z, grid.radius,
                              [&](unsigned int begin, unsigned int end) {
                                for (unsigned int k = begin; k < end; ++k)
                                  f(k);
                              });
}

__device__ float pairAppearance(const kernels::KernelConstants& k, const CloudView& target, int i,
                                const CloudView& source, int j) {
  const float d2 = kernels::appearanceDistance2(
      k, k.use_color ? target.colors + kernels::kColorDim * i : nullptr,
      k.use_color ? source.colors + kernels::kColorDim * j : nullptr,
      k.semantic_classes ? target.semantics + k.semantic_classes * i : nullptr,
      k.semantic_classes ? source.semantics + k.semantic_classes * j : nullptr);
  return kernels::appearanceWeight(k, d2);
}

// Block-wide sum into thread 0 in a fixed tree order (deterministic run to run).
template <class Sums, class Add>
__device__ void blockReduce(Sums* shared, Sums value, Add add) {
  shared[threadIdx.x] = value;
  __syncthreads();
  for (int stride = blockDim.x / 2; stride > 0; stride /= 2) {
    if (threadIdx.x < stride) add(shared[threadIdx.x], shared[threadIdx.x + stride]);
    __syncthreads();
  }
}

// Calls f(x, a) for every candidate target point x of source point j (at z), with the pair's
// retained weight a (0 when not retained).
template <class F>
__device__ void forEachPairWeight(const CloudView& target, const CloudView& source,
                                  const GridView& grid, const kernels::KernelConstants& k, int j,
                                  const float* z, float inv_two_ell2, F&& f) {
  forEachCandidate(grid, z, [&](unsigned int i) {
    const float* x = target.positions + 3 * i;
    f(x, kernels::retainedPairWeight(pairAppearance(k, target, i, source, j), x[0] - z[0],
                                     x[1] - z[1], x[2] - z[2], inv_two_ell2, k.sp_thres));
  });
}

// Source point j's moment sums over its candidates.
__device__ kernels::PointSums pointSums(const CloudView& target, const CloudView& source,
                                        const GridView& grid, const kernels::KernelConstants& k,
                                        int j, const float* z, float inv_two_ell2) {
  kernels::PointSums sums;
  kernels::clear(sums);
  forEachPairWeight(target, source, grid, k, j, z, inv_two_ell2, [&](const float* x, float a) {
    kernels::accumulatePair(sums, a, x[0] - z[0], x[1] - z[1], x[2] - z[2]);
  });
  return sums;
}

// One thread a source point: per_point(j, T z_j, sums) adds the point's share to the thread's
// sums; the block's sums are added in a fixed tree order, one partial a block.
template <class Sums, class PerPoint>
__global__ void sourcePointsKernel(CloudView source, Pose3x4 pose, PerPoint per_point,
                                   Sums* partial) {
  __shared__ Sums shared[kThreads];
  const int j = blockIdx.x * blockDim.x + threadIdx.x;
  Sums mine;
  kernels::clear(mine);
  if (j < source.count) {
    float z[3];
    kernels::transformPoint(pose.m, source.positions + 3 * j, z);
    per_point(j, z, mine);
  }
  blockReduce(shared, mine, [](Sums& a, const Sums& b) { kernels::add(a, b); });
  if (threadIdx.x == 0) partial[blockIdx.x] = shared[0];
}

// Grid build: the cell of every target point and the points per cell.
__global__ void cellKernel(const float* positions, int count, GridView grid, unsigned int* cell,
                           unsigned int* counts) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= count) return;
  cell[i] = static_cast<unsigned int>(kernels::cellOfPoint(grid.shape, positions + 3 * i));
  atomicAdd(&counts[cell[i]], 1u);
}

// The per-block partial sums into one: thread t adds blocks t, t + kThreads, ... in order, then a
// fixed tree (deterministic run to run).
template <class Sums>
__global__ void finalSumKernel(const Sums* partial, int blocks, Sums* total) {
  __shared__ Sums shared[kThreads];
  Sums mine;
  kernels::clear(mine);
  for (int b = threadIdx.x; b < blocks; b += blockDim.x)
    kernels::add(mine, partial[b]);
  blockReduce(shared, mine, [](Sums& a, const Sums& b) { kernels::add(a, b); });
  if (threadIdx.x == 0) *total = shared[0];
}

__global__ void iotaKernel(unsigned int* values, int count) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < count) values[i] = static_cast<unsigned int>(i);
}

__global__ void gatherKernel(const unsigned int* order, int count, const float* positions,
                             const float* colors, const float* semantics, int classes,
                             float* out_positions, float* out_colors, float* out_semantics) {
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= count) return;
  const unsigned int i = order[k];
  for (int a = 0; a < 3; ++a)
    out_positions[3 * k + a] = positions[3 * i + a];
  if (colors) {
    for (int a = 0; a < kernels::kColorDim; ++a) {
      out_colors[kernels::kColorDim * k + a] = colors[kernels::kColorDim * i + a];
    }
  }
  for (int a = 0; a < classes; ++a)
    out_semantics[classes * k + a] = semantics[classes * i + a];
}

}  // namespace

struct DevicePairSums::Impl {
  cudaStream_t stream = nullptr;
  // Raw uploads and the target sorted by cell.
  DeviceBuffer<float> raw[2][3];  // [target/source][positions, colors, semantics]
  DeviceBuffer<float> sorted[3];  // target in cell order
  DeviceBuffer<unsigned int> cell, sorted_cell, counts, start, iota, order;
  DeviceBuffer<unsigned char> scratch;  // CUB's temporary storage
  DeviceBuffer<kernels::MomentSums> moment_partials;
  DeviceBuffer<kernels::TaylorSums> taylor_partials;
  DeviceBuffer<kernels::MomentSums> moment_total;
  DeviceBuffer<kernels::TaylorSums> taylor_total;
  DeviceBuffer<kernels::CurvatureSums> curvature_partials, curvature_total;
  float* pinned = nullptr;  // staging for uploads
  std::size_t pinned_capacity = 0;
  kernels::MomentSums* pinned_moments = nullptr;  // the one download of an evaluation
  kernels::TaylorSums* pinned_taylor = nullptr;
  kernels::CurvatureSums* pinned_curvature = nullptr;
  int count[2] = {0, 0};
  int classes = 0;
  bool target_has_color = false;
  std::vector<float> host_positions;  // target positions, for the bounding box
  kernels::KernelConstants constants{};
  double cutoff2 = 0.0;
  double grid_cell = -1.0;
  GridView grid{};

  // Uploads the three arrays of a cloud through one pinned staging buffer and one wait.
  void upload(int which, const float* const* data, const std::size_t* sizes) {
    const std::size_t total = sizes[0] + sizes[1] + sizes[2];
    if (total > pinned_capacity) {
      if (pinned) cudaFreeHost(pinned);
      pinned = nullptr;
      pinned_capacity = 0;
      check(cudaMallocHost(&pinned, total * sizeof(float)), "cudaMallocHost");
      pinned_capacity = total;
    }
    std::size_t offset = 0;
    for (int a = 0; a < 3; ++a) {
      raw[which][a].reserve(sizes[a]);
      if (sizes[a] == 0) continue;
      std::copy(data[a], data[a] + sizes[a], pinned + offset);
      check(cudaMemcpyAsync(raw[which][a].data, pinned + offset, sizes[a] * sizeof(float),
                            cudaMemcpyHostToDevice, stream),
            "upload");
      offset += sizes[a];
    }
    check(cudaStreamSynchronize(stream), "upload sync");  // the staging buffer is reused
  }

  // The target sorted by grid cell (a stable radix sort of the cell indices) and each cell's
  // first point (an exclusive scan of the cell counts), all on the device, no host wait.
  void buildGrid(double cell_size) {
    const int n = count[0];
    float lo[3], hi[3];
    kernels::boundingBox(host_positions.data(), n, lo, hi);
    // Coarsen the cells when the box is huge (outdoor): still exact, just more points scanned.
    float edge = static_cast<float>(cell_size);
    double cells = kernels::shapeOverBox(lo, hi, edge, &grid.shape);
    while (cells > kernels::kMaxDenseCells) {
      edge *= 1.5f;
      cells = kernels::shapeOverBox(lo, hi, edge, &grid.shape);
    }
    const auto total = static_cast<std::size_t>(cells);
    int cell_bits = 1;
    while ((std::size_t{1} << cell_bits) < total)
      ++cell_bits;
    std::size_t scan_bytes = 0, sort_bytes = 0;
    check(cub::DeviceScan::ExclusiveSum(nullptr, scan_bytes, counts.data, start.data,
                                        static_cast<int>(total + 1), stream),
          "scan size");
    check(cub::DeviceRadixSort::SortPairs(nullptr, sort_bytes, cell.data, sorted_cell.data,
                                          iota.data, order.data, n, 0, cell_bits, stream),
          "sort size");
    reserveGrid(n, total, std::max(scan_bytes, sort_bytes));
    check(cudaMemsetAsync(counts.data, 0, (total + 1) * sizeof(unsigned int), stream), "memset");
    if (n > 0) {
      const int blocks = (n + kThreads - 1) / kThreads;
      cellKernel<<<blocks, kThreads, 0, stream>>>(raw[0][0].data, n, grid, cell.data, counts.data);
      iotaKernel<<<blocks, kThreads, 0, stream>>>(iota.data, n);
      check(cudaGetLastError(), "cell kernels");
    }
    // counts[total] stays 0, so the scan gives start[c] = first point of cell c and
    // start[total] = n.
    scan_bytes = scratch.capacity;
    check(cub::DeviceScan::ExclusiveSum(scratch.data, scan_bytes, counts.data, start.data,
                                        static_cast<int>(total + 1), stream),
          "scan");
    if (n > 0) {
      sort_bytes = scratch.capacity;
      check(cub::DeviceRadixSort::SortPairs(scratch.data, sort_bytes, cell.data, sorted_cell.data,
                                            iota.data, order.data, n, 0, cell_bits, stream),
            "sort");
      const int blocks = (n + kThreads - 1) / kThreads;
      gatherKernel<<<blocks, kThreads, 0, stream>>>(
          order.data, n, raw[0][0].data, target_has_color ? raw[0][1].data : nullptr,
          raw[0][2].data, classes, sorted[0].data, sorted[1].data, sorted[2].data);
      check(cudaGetLastError(), "gather kernel");
    }
    grid.start = start.data;
    grid.radius = static_cast<float>(cell_size);
    grid_cell = cell_size;
  }

  void reserveGrid(int n, std::size_t total, std::size_t scratch_bytes) {
    cell.reserve(n);
    sorted_cell.reserve(n);
    iota.reserve(n);
    order.reserve(n);
    counts.reserve(total + 1);
    start.reserve(total + 1);
    scratch.reserve(scratch_bytes);
    sorted[0].reserve(3 * static_cast<std::size_t>(n));
    sorted[1].reserve(kernels::kColorDim * static_cast<std::size_t>(n));
    sorted[2].reserve(static_cast<std::size_t>(classes) * n);
  }

  // Grid for this lengthscale (rebuilt when it changed); returns the number of blocks, one
  // source point a thread.
  int prepare(double ell) {
    const double radius = std::sqrt(cutoff2) * ell;
    if (grid_cell != radius) buildGrid(radius);
    return std::max(1, (count[1] + kThreads - 1) / kThreads);
  }

  // Adds the per-block partial sums on the device and waits for the one result.
  template <class Sums>
  Sums sumPartials(const DeviceBuffer<Sums>& partials, int blocks, DeviceBuffer<Sums>& total,
                   Sums* pinned_total) {
    total.reserve(1);
    finalSumKernel<<<1, kThreads, 0, stream>>>(partials.data, blocks, total.data);
    check(cudaGetLastError(), "sum kernel");
    check(cudaMemcpyAsync(pinned_total, total.data, sizeof(Sums), cudaMemcpyDeviceToHost, stream),
          "download sums");
    check(cudaStreamSynchronize(stream), "sums sync");
    return *pinned_total;
  }

  // The grid for `ell` and the kernel's inputs.
  Evaluation evaluation(const float* pose, double ell) {
    Evaluation e;
    e.blocks = prepare(ell);
    std::copy(pose, pose + 12, e.pose.m);
    e.target = targetView();
    e.source = sourceView();
    e.grid = grid;
    e.k = constants;
    e.inv_two_ell2 = static_cast<float>(0.5 / (ell * ell));
    e.inv_ell2 = 1.0 / (ell * ell);
    return e;
  }

  // Runs per_point over every source point and returns the summed result (one host wait).
  template <class Sums, class PerPoint>
  Sums run(const Evaluation& e, PerPoint per_point, DeviceBuffer<Sums>& partials,
           DeviceBuffer<Sums>& total, Sums* pinned_total, const char* what) {
    partials.reserve(e.blocks);
    sourcePointsKernel<<<e.blocks, kThreads, 0, stream>>>(e.source, e.pose, per_point,
                                                          partials.data);
    check(cudaGetLastError(), what);
    return sumPartials(partials, e.blocks, total, pinned_total);
  }

  CloudView targetView() const {
    return {sorted[0].data, sorted[1].data, sorted[2].data, count[0]};
  }
  CloudView sourceView() const {
    return {raw[1][0].data, raw[1][1].data, raw[1][2].data, count[1]};
  }
};

DevicePairSums::DevicePairSums() : impl_(std::make_unique<Impl>()) {
  check(cudaStreamCreateWithFlags(&impl_->stream, cudaStreamNonBlocking), "cudaStreamCreate");
  check(cudaMallocHost(&impl_->pinned_moments, sizeof(kernels::MomentSums)), "cudaMallocHost");
  check(cudaMallocHost(&impl_->pinned_taylor, sizeof(kernels::TaylorSums)), "cudaMallocHost");
  check(cudaMallocHost(&impl_->pinned_curvature, sizeof(kernels::CurvatureSums)), "cudaMallocHost");
}

DevicePairSums::~DevicePairSums() {
  if (impl_->pinned) cudaFreeHost(impl_->pinned);
  if (impl_->pinned_moments) cudaFreeHost(impl_->pinned_moments);
  if (impl_->pinned_taylor) cudaFreeHost(impl_->pinned_taylor);
  if (impl_->pinned_curvature) cudaFreeHost(impl_->pinned_curvature);
  if (impl_->stream) cudaStreamDestroy(impl_->stream);
}

void DevicePairSums::setCloud(bool target, const float* positions, const float* colors,
                              const float* semantics, int count, int classes) {
  Impl& d = *impl_;
  const int which = target ? 0 : 1;
  d.count[which] = count;
  d.classes = classes;
  if (target) d.target_has_color = colors != nullptr;
  const auto n = static_cast<std::size_t>(count);
  const float* data[3] = {positions, colors, semantics};
  const std::size_t sizes[3] = {3 * n, colors ? kernels::kColorDim * n : 0,
                                semantics ? static_cast<std::size_t>(classes) * n : 0};
  d.upload(which, data, sizes);
  if (target) {
    d.host_positions.assign(positions, positions + 3 * n);
    d.grid_cell = -1.0;  // rebuilt at the next evaluation
  }
}

void DevicePairSums::setConstants(const kernels::KernelConstants& constants, double cutoff2) {
  impl_->constants = constants;
  impl_->cutoff2 = cutoff2;
  impl_->grid_cell = -1.0;
}

kernels::MomentSums DevicePairSums::moments(const float* pose, double ell) {
  Impl& d = *impl_;
  const Evaluation e = d.evaluation(pose, ell);
  auto per_point = [=] __device__(int j, const float* z, kernels::MomentSums& mine) {
    const kernels::PointSums sums =
        pointSums(e.target, e.source, e.grid, e.k, j, z, e.inv_two_ell2);
    if (sums.pairs > 0) kernels::accumulatePoint(mine, sums, z);
  };
  return d.run(e, per_point, d.moment_partials, d.moment_total, d.pinned_moments, "moments kernel");
}

kernels::TaylorSums DevicePairSums::taylor(const float* pose, const double* xi, double ell) {
  Impl& d = *impl_;
  const Evaluation e = d.evaluation(pose, ell);
  Twist twist;
  std::copy(xi, xi + 6, twist.v);
  auto per_point = [=] __device__(int j, const float* z, kernels::TaylorSums& mine) {
    kernels::TaylorFrame frame;
    kernels::makeTaylorFrame(z, twist.v, frame);
    forEachPairWeight(e.target, e.source, e.grid, e.k, j, z, e.inv_two_ell2,
                      [&](const float* x, float a) {
                        if (a > 0.0f)
                          kernels::accumulateTaylorPair(mine, frame, x, z, a, e.inv_ell2);
                      });
  };
  return d.run(e, per_point, d.taylor_partials, d.taylor_total, d.pinned_taylor, "taylor kernel");
}

kernels::CurvatureSums DevicePairSums::curvature(const float* pose, double ell) {
  Impl& d = *impl_;
  const Evaluation e = d.evaluation(pose, ell);
  // Moments over every source point, the Hessian from every kCurvatureStride-th (as the CPU).
  auto per_point = [=] __device__(int j, const float* z, kernels::CurvatureSums& mine) {
    if (j % kernels::kCurvatureStride != 0) {
      const kernels::PointSums sums =
          pointSums(e.target, e.source, e.grid, e.k, j, z, e.inv_two_ell2);
      if (sums.pairs > 0) kernels::accumulatePoint(mine.moments, sums, z);
      return;
    }
    kernels::PointCurvature sums;
    kernels::clear(sums);
    const float inv_shell_width = kernels::inverseShellWidth(e.k.sp_thres);
    forEachPairWeight(
        e.target, e.source, e.grid, e.k, j, z, e.inv_two_ell2, [&](const float* x, float a) {
          kernels::accumulateCurvaturePair(sums, a, x[0] - z[0], x[1] - z[1], x[2] - z[2],
                                           e.k.sp_thres, inv_shell_width);
        });
    kernels::accumulatePointCurvature(mine, sums, z, e.inv_ell2, kernels::kCurvatureStride);
  };
  return d.run(e, per_point, d.curvature_partials, d.curvature_total, d.pinned_curvature,
               "curvature kernel");
}

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
