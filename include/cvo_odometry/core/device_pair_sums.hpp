// The device side of the device backends, with a plain interface (no Eigen, no Thrust or CUDA
// types). One Thrust source (src/core/cuda/device_pair_sums.cu) is built twice: by nvcc for a
// CUDA GPU (DeviceSystem::kCuda, the `cuda` backend) and by the host compiler for OpenMP threads
// (DeviceSystem::kOmp, the `device_cpu` backend, which runs the GPU's code where there is no GPU).
// Device vectors persist and grow; the target's neighbour grid (dense_grid.hpp, shared with the
// CPU) is built on the device (cell of each point, stable sort, cell ranges by binary search);
// each evaluation is one transform_reduce over the source points, deterministic run to run.
// Every call throws std::runtime_error naming what failed (a CUDA error, device memory).
#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include "cvo_odometry/core/pair_kernels.hpp"

namespace cvo {

enum class DeviceSystem { kCuda, kOmp };

// What the device code has been asked to do so far, the same count on both systems (the fixed
// costs a registration pays per call, measured where no GPU is: cvo_benchmark --time-calls on
// device_cpu). Thrust algorithms: on CUDA each is one or more kernel launches (a reduction two
// and a copy back, the grid's stable sort several). The host waits once per evaluation (for its
// sums) and once per upload.
struct DeviceWork {
  long algorithms = 0;   // Thrust algorithms run, grid builds' and evaluations' together
  long grid_builds = 0;  // the target's neighbour grid (4 algorithms and a gather per array)
  long evaluations = 0;  // moments, Taylor or curvature sums: one reduction each
  long uploads = 0;      // clouds copied to the device (once a registration, not a level)
};

template <DeviceSystem System>
class DevicePairSums {
 public:
  // `threads`: OpenMP threads of the reductions (kOmp; 0: OpenMP's default); unused on CUDA.
  explicit DevicePairSums(int threads = 0);
  ~DevicePairSums();
  DevicePairSums(const DevicePairSums&) = delete;
  DevicePairSums& operator=(const DevicePairSums&) = delete;

  // Positions: 3 floats a point; colours kColorDim floats a point or null; semantics
  // `classes` floats a point or null.
  void setCloud(bool target, const float* positions, const float* colors, const float* semantics,
                int count, int classes);
  // From the next evaluation on, sum over the target's every target_stride-th point and the
  // source's every source_stride-th, or source_count points spread evenly over it where
  // source_count is not 0 (CloudSubsets): indices into the clouds on the device, no upload.
  // setCloud starts again from every point.
  void useSubsets(std::size_t target_stride, std::size_t source_stride, std::size_t source_count);
  void setConstants(const kernels::KernelConstants& constants, double cutoff2);
  // Sums with the source moved by the row-major 3x4 `pose`, at lengthscale `ell`.
  kernels::MomentSums moments(const float* pose, double ell);
  kernels::TaylorSums taylor(const float* pose, const double* xi, double ell);
  kernels::CurvatureSums curvature(const float* pose, double ell);

  const DeviceWork& work() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// True when a CUDA device can be used; otherwise false with the reason.
bool cudaDeviceUsable(std::string* why_not);

}  // namespace cvo
