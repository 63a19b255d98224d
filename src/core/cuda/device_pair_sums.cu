#include <cuda_runtime.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "cvo_odometry/core/device_pair_sums.hpp"

namespace cvo {

namespace {

constexpr int kThreads = 128;  // one source point a thread, one partial sum a block
constexpr double kMaxDenseCells = 4.0e6;

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
    check(cudaMalloc(&data, std::max<std::size_t>(n, 1) * sizeof(T)), "cudaMalloc");
    capacity = n;
  }
  ~DeviceBuffer() {
    if (data) cudaFree(data);
  }
};

struct GridView {
  float origin[3];
  float cell;
  int dims[3];
  const unsigned int* start;  // dims product + 1 offsets into the sorted target arrays
};

struct CloudView {
  const float* positions;
  const float* colors;
  const float* semantics;
  int count;
};

__device__ int cellOf(float v, float origin, float cell) {
  return static_cast<int>(floorf((v - origin) / cell));
}

// Visits the target points of the 9 z-columns around z (the grid cell is the query radius).
template <class F>
__device__ void forEachCandidate(const GridView& grid, const float* z, F&& f) {
  const int cx = cellOf(z[0], grid.origin[0], grid.cell);
  const int cy = cellOf(z[1], grid.origin[1], grid.cell);
  const int cz = cellOf(z[2], grid.origin[2], grid.cell);
  for (int dx = -1; dx <= 1; ++dx) {
    for (int dy = -1; dy <= 1; ++dy) {
      const int x = cx + dx, y = cy + dy;
      if (x < 0 || y < 0 || x >= grid.dims[0] || y >= grid.dims[1]) continue;
      const int z0 = max(cz - 1, 0), z1 = min(cz + 1, grid.dims[2] - 1);
      if (z0 > z1) continue;
      const std::size_t column = (static_cast<std::size_t>(x) * grid.dims[1] + y) * grid.dims[2];
      for (unsigned int k = grid.start[column + z0]; k < grid.start[column + z1 + 1]; ++k)
        f(k);
    }
  }
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

__global__ void momentsKernel(CloudView target, CloudView source, GridView grid,
                              kernels::KernelConstants k, const float* pose, float inv_two_ell2,
                              kernels::MomentSums* partial) {
  __shared__ kernels::MomentSums shared[kThreads];
  const int j = blockIdx.x * blockDim.x + threadIdx.x;
  kernels::MomentSums mine;
  kernels::clear(mine);
  if (j < source.count) {
    float z[3];
    kernels::transformPoint(pose, source.positions + 3 * j, z);
    kernels::PointSums sums;
    kernels::clear(sums);
    forEachCandidate(grid, z, [&](unsigned int i) {
      const float* x = target.positions + 3 * i;
      const float a =
          kernels::retainedPairWeight(pairAppearance(k, target, i, source, j), x[0] - z[0],
                                      x[1] - z[1], x[2] - z[2], inv_two_ell2, k.sp_thres);
      kernels::accumulatePair(sums, a, x[0] - z[0], x[1] - z[1], x[2] - z[2]);
    });
    if (sums.pairs > 0) kernels::accumulatePoint(mine, sums, z);
  }
  blockReduce(shared, mine,
              [](kernels::MomentSums& a, const kernels::MomentSums& b) { kernels::add(a, b); });
  if (threadIdx.x == 0) partial[blockIdx.x] = shared[0];
}

__global__ void taylorKernel(CloudView target, CloudView source, GridView grid,
                             kernels::KernelConstants k, const float* pose, const double* xi,
                             float inv_two_ell2, double inv_ell2, kernels::TaylorSums* partial) {
  __shared__ kernels::TaylorSums shared[kThreads];
  const int j = blockIdx.x * blockDim.x + threadIdx.x;
  kernels::TaylorSums mine{0.0, 0.0, 0.0, 0.0};
  if (j < source.count) {
    float z[3];
    kernels::transformPoint(pose, source.positions + 3 * j, z);
    kernels::TaylorFrame frame;
    kernels::makeTaylorFrame(z, xi, frame);
    forEachCandidate(grid, z, [&](unsigned int i) {
      const float* x = target.positions + 3 * i;
      const float a =
          kernels::retainedPairWeight(pairAppearance(k, target, i, source, j), x[0] - z[0],
                                      x[1] - z[1], x[2] - z[2], inv_two_ell2, k.sp_thres);
      if (a > 0.0f) kernels::accumulateTaylorPair(mine, frame, x, z, a, inv_ell2);
    });
  }
  blockReduce(shared, mine,
              [](kernels::TaylorSums& a, const kernels::TaylorSums& b) { kernels::add(a, b); });
  if (threadIdx.x == 0) partial[blockIdx.x] = shared[0];
}

// Grid build: cell of every target point, counting sort into cell order.
__global__ void cellKernel(const float* positions, int count, GridView grid, unsigned int* cell,
                           unsigned int* counts) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= count) return;
  const float* p = positions + 3 * i;
  int c[3];
  for (int a = 0; a < 3; ++a) {
    c[a] = min(max(cellOf(p[a], grid.origin[a], grid.cell), 0), grid.dims[a] - 1);
  }
  cell[i] = static_cast<unsigned int>(
      (static_cast<std::size_t>(c[0]) * grid.dims[1] + c[1]) * grid.dims[2] + c[2]);
  atomicAdd(&counts[cell[i] + 1], 1u);
}

// Stable scatter (one thread walks the points in order: stable, and cheap for < 100k points).
__global__ void scatterKernel(const unsigned int* cell, int count, unsigned int* fill,
                              unsigned int* order) {
  if (blockIdx.x != 0 || threadIdx.x != 0) return;
  for (int i = 0; i < count; ++i)
    order[fill[cell[i]]++] = static_cast<unsigned int>(i);
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
  DeviceBuffer<unsigned int> cell, start, fill, order;
  DeviceBuffer<float> pose;
  DeviceBuffer<double> xi;
  DeviceBuffer<kernels::MomentSums> moment_partials;
  DeviceBuffer<kernels::TaylorSums> taylor_partials;
  float* pinned = nullptr;  // staging for uploads
  std::size_t pinned_capacity = 0;
  int count[2] = {0, 0};
  int classes = 0;
  bool has_color[2] = {false, false};
  std::vector<float> host_positions;  // target positions, for the bounding box
  kernels::KernelConstants constants{};
  double cutoff2 = 0.0;
  double grid_cell = -1.0;
  GridView grid{};
  std::vector<kernels::MomentSums> host_moments;
  std::vector<kernels::TaylorSums> host_taylor;

  void upload(DeviceBuffer<float>& buffer, const float* data, std::size_t n) {
    buffer.reserve(n);
    if (n == 0) return;
    if (n > pinned_capacity) {
      if (pinned) cudaFreeHost(pinned);
      pinned = nullptr;
      check(cudaMallocHost(&pinned, n * sizeof(float)), "cudaMallocHost");
      pinned_capacity = n;
    }
    std::copy(data, data + n, pinned);
    check(cudaMemcpyAsync(buffer.data, pinned, n * sizeof(float), cudaMemcpyHostToDevice, stream),
          "upload");
    check(cudaStreamSynchronize(stream), "upload sync");  // the staging buffer is reused
  }

  void buildGrid(double cell_size) {
    const int n = count[0];
    float lo[3], hi[3];
    for (int a = 0; a < 3; ++a)
      lo[a] = hi[a] = n ? host_positions[a] : 0.0f;
    for (int i = 0; i < n; ++i) {
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], host_positions[3 * i + a]);
        hi[a] = std::max(hi[a], host_positions[3 * i + a]);
      }
    }
    // Coarsen the cells when the box is huge (outdoor): still exact, just more points scanned.
    double edge = cell_size;
    auto cells = [&](double c) {
      double total = 1.0;
      for (int a = 0; a < 3; ++a)
        total *= std::floor((hi[a] - lo[a]) / c) + 1.0;
      return total;
    };
    while (cells(edge) > kMaxDenseCells)
      edge *= 1.5;
    grid.cell = static_cast<float>(edge);
    std::size_t total = 1;
    for (int a = 0; a < 3; ++a) {
      grid.origin[a] = lo[a];
      grid.dims[a] = static_cast<int>(std::floor((hi[a] - lo[a]) / edge)) + 1;
      total *= static_cast<std::size_t>(grid.dims[a]);
    }
    reserveGrid(n, total);
    check(cudaMemsetAsync(start.data, 0, (total + 1) * sizeof(unsigned int), stream), "memset");
    const int blocks = (n + kThreads - 1) / kThreads;
    if (n > 0) {
      cellKernel<<<blocks, kThreads, 0, stream>>>(raw[0][0].data, n, grid, cell.data, start.data);
      check(cudaGetLastError(), "cell kernel");
    }
    // Prefix sum of the counts on the host (dims are small; a device scan is not worth it here).
    std::vector<unsigned int> offsets(total + 1);
    check(cudaMemcpyAsync(offsets.data(), start.data, (total + 1) * sizeof(unsigned int),
                          cudaMemcpyDeviceToHost, stream),
          "download counts");
    check(cudaStreamSynchronize(stream), "counts sync");
    for (std::size_t c = 1; c <= total; ++c)
      offsets[c] += offsets[c - 1];
    check(cudaMemcpyAsync(start.data, offsets.data(), (total + 1) * sizeof(unsigned int),
                          cudaMemcpyHostToDevice, stream),
          "upload offsets");
    check(cudaMemcpyAsync(fill.data, offsets.data(), total * sizeof(unsigned int),
                          cudaMemcpyHostToDevice, stream),
          "upload fill");
    if (n > 0) {
      scatterKernel<<<1, 1, 0, stream>>>(cell.data, n, fill.data, order.data);
      gatherKernel<<<blocks, kThreads, 0, stream>>>(
          order.data, n, raw[0][0].data, has_color[0] ? raw[0][1].data : nullptr, raw[0][2].data,
          classes, sorted[0].data, sorted[1].data, sorted[2].data);
      check(cudaGetLastError(), "grid kernels");
    }
    check(cudaStreamSynchronize(stream), "grid sync");
    grid.start = start.data;
    grid_cell = cell_size;
  }

  void reserveGrid(int n, std::size_t total) {
    cell.reserve(n);
    order.reserve(n);
    start.reserve(total + 1);
    fill.reserve(total);
    sorted[0].reserve(3 * static_cast<std::size_t>(n));
    sorted[1].reserve(kernels::kColorDim * static_cast<std::size_t>(n));
    sorted[2].reserve(static_cast<std::size_t>(classes) * n);
  }

  // Grid for this lengthscale (rebuilt when it changed) and the pose on the device; returns the
  // number of blocks, one source point a thread.
  int prepare(const float* host_pose, double ell) {
    const double radius = std::sqrt(cutoff2) * ell;
    if (grid_cell != radius) buildGrid(radius);
    check(cudaMemcpyAsync(pose.data, host_pose, 12 * sizeof(float), cudaMemcpyHostToDevice, stream),
          "upload pose");
    return std::max(1, (count[1] + kThreads - 1) / kThreads);
  }

  // Downloads the per-block partial sums and adds them in block order (deterministic).
  template <class Sums>
  Sums sumPartials(const DeviceBuffer<Sums>& partials, std::vector<Sums>& host, int blocks) {
    host.resize(blocks);
    check(cudaMemcpyAsync(host.data(), partials.data, blocks * sizeof(Sums), cudaMemcpyDeviceToHost,
                          stream),
          "download partial sums");
    check(cudaStreamSynchronize(stream), "sums sync");
    Sums total{};
    for (const Sums& partial : host)
      kernels::add(total, partial);
    return total;
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
  impl_->pose.reserve(12);
  impl_->xi.reserve(6);
}

DevicePairSums::~DevicePairSums() {
  if (impl_->pinned) cudaFreeHost(impl_->pinned);
  if (impl_->stream) cudaStreamDestroy(impl_->stream);
}

void DevicePairSums::setCloud(bool target, const float* positions, const float* colors,
                              const float* semantics, int count, int classes) {
  Impl& d = *impl_;
  const int which = target ? 0 : 1;
  d.count[which] = count;
  d.classes = classes;
  d.has_color[which] = colors != nullptr;
  d.upload(d.raw[which][0], positions, 3 * static_cast<std::size_t>(count));
  d.upload(d.raw[which][1], colors ? colors : positions,
           colors ? kernels::kColorDim * static_cast<std::size_t>(count) : 0);
  d.upload(d.raw[which][2], semantics ? semantics : positions,
           semantics ? static_cast<std::size_t>(classes) * count : 0);
  if (target) {
    d.host_positions.assign(positions, positions + 3 * static_cast<std::size_t>(count));
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
  const int blocks = d.prepare(pose, ell);
  d.moment_partials.reserve(blocks);
  momentsKernel<<<blocks, kThreads, 0, d.stream>>>(
      d.targetView(), d.sourceView(), d.grid, d.constants, d.pose.data,
      static_cast<float>(0.5 / (ell * ell)), d.moment_partials.data);
  check(cudaGetLastError(), "moments kernel");
  return d.sumPartials(d.moment_partials, d.host_moments, blocks);
}

kernels::TaylorSums DevicePairSums::taylor(const float* pose, const double* xi, double ell) {
  Impl& d = *impl_;
  const int blocks = d.prepare(pose, ell);
  d.taylor_partials.reserve(blocks);
  check(cudaMemcpyAsync(d.xi.data, xi, 6 * sizeof(double), cudaMemcpyHostToDevice, d.stream),
        "upload twist");
  taylorKernel<<<blocks, kThreads, 0, d.stream>>>(
      d.targetView(), d.sourceView(), d.grid, d.constants, d.pose.data, d.xi.data,
      static_cast<float>(0.5 / (ell * ell)), 1.0 / (ell * ell), d.taylor_partials.data);
  check(cudaGetLastError(), "taylor kernel");
  return d.sumPartials(d.taylor_partials, d.host_taylor, blocks);
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
