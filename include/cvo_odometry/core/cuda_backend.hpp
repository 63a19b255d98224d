// CUDA backend: the same sums as the CPU backend, per source point on the GPU (one thread a
// point, the target's grid built on the device), with the shared pair kernels.
#pragma once

#include <memory>

#include "cvo_odometry/core/device_pair_sums.hpp"
#include "cvo_odometry/core/registration_backend.hpp"

namespace cvo {

class CudaBackend : public RegistrationBackend {
 public:
  CudaBackend();
  std::string name() const override { return "cuda"; }
  void setProblem(const LabeledCloud& target, const LabeledCloud& source,
                  const CvoParams& params) override;
  kernels::MomentSums moments(const Eigen::Isometry3d& T, double ell) override;
  kernels::TaylorSums taylor(const Eigen::Isometry3d& T, const Vector6d& xi, double ell) override;
  kernels::CurvatureSums curvature(const Eigen::Isometry3d& T, double ell) override;

 private:
  DevicePairSums device_;
};

}  // namespace cvo
