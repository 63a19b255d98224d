// The CUDA side of the CUDA backend, with a plain interface (no Eigen, no CUDA types) so that
// only src/core/cuda/device_pair_sums.cu needs nvcc. Device buffers persist and grow; clouds are
// uploaded through pinned staging memory; the target's neighbour grid (dense_grid.hpp, shared
// with the CPU) is built on the GPU by a stable radix sort of the cell indices, without a host
// wait; an evaluation sums on the device and waits once, for its result.
// Every call throws std::runtime_error naming the failing CUDA call.
#pragma once

#include <memory>
#include <string>

#include "cvo_odometry/core/pair_kernels.hpp"

namespace cvo {

class DevicePairSums {
 public:
  DevicePairSums();
  ~DevicePairSums();
  DevicePairSums(const DevicePairSums&) = delete;
  DevicePairSums& operator=(const DevicePairSums&) = delete;

  // Positions: 3 floats a point; colours kColorDim floats a point or null; semantics
  // `classes` floats a point or null.
  void setCloud(bool target, const float* positions, const float* colors, const float* semantics,
                int count, int classes);
  void setConstants(const kernels::KernelConstants& constants, double cutoff2);
  // Sums with the source moved by the row-major 3x4 `pose`, at lengthscale `ell`.
  kernels::MomentSums moments(const float* pose, double ell);
  kernels::TaylorSums taylor(const float* pose, const double* xi, double ell);
  kernels::CurvatureSums curvature(const float* pose, double ell);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// True when a CUDA device can be used; otherwise false with the reason.
bool cudaDeviceUsable(std::string* why_not);

}  // namespace cvo
