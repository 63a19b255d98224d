// The device backends: the same sums as the CPU backend, one transform_reduce over the source
// points on the device (the target's grid built there), with the shared pair kernels. One source
// built for two systems (device_pair_sums.hpp): `cuda` on a GPU, and `device_cpu` on OpenMP
// threads, which runs the GPU's code on machines without one (the parity tests in CI).
#pragma once

#include <string>

#include "cvo_odometry/core/device_pair_sums.hpp"
#include "cvo_odometry/core/registration_backend.hpp"

namespace cvo {

template <DeviceSystem System>
class DeviceBackend : public RegistrationBackend {
 public:
  // `num_threads`: device_cpu's reduction threads (0: OpenMP's default); unused on CUDA.
  explicit DeviceBackend(int num_threads = 0);
  std::string name() const override;
  void setProblem(const LabeledCloud& target, const LabeledCloud& source,
                  const CvoParams& params) override;
  void useSubsets(const CloudSubsets& subsets) override;
  kernels::MomentSums moments(const Eigen::Isometry3d& T, double ell) override;
  kernels::TaylorSums taylor(const Eigen::Isometry3d& T, const Vector6d& xi, double ell) override;
  kernels::CurvatureSums curvature(const Eigen::Isometry3d& T, double ell) override;
  std::optional<DeviceWork> deviceWork() const override { return device_.work(); }

 private:
  DevicePairSums<System> device_;
};

using CudaBackend = DeviceBackend<DeviceSystem::kCuda>;      // built with CVO_HAVE_CUDA
using DeviceCpuBackend = DeviceBackend<DeviceSystem::kOmp>;  // built with CVO_HAVE_DEVICE_CPU

}  // namespace cvo
