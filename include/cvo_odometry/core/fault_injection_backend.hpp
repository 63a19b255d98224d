// A test hook: wraps a backend and, from its `good_calls`-th evaluation on, throws
// std::runtime_error as a GPU that fails mid-run would. Wrapped in a FailoverBackend it exercises
// the CPU fallback on machines without a GPU (the nodelet's inject_backend_fault_after).
#pragma once

#include <memory>
#include <string>

#include "cvo_odometry/core/registration_backend.hpp"

namespace cvo {

class FaultInjectionBackend : public RegistrationBackend {
 public:
  FaultInjectionBackend(std::unique_ptr<RegistrationBackend> inner, long good_calls);

  std::string name() const override;
  void setProblem(const LabeledCloud& target, const LabeledCloud& source,
                  const CvoParams& params) override;
  void useSubsets(const CloudSubsets& subsets) override;
  kernels::MomentSums moments(const Eigen::Isometry3d& T, double ell) override;
  kernels::MomentSums oneOffMoments(const Eigen::Isometry3d& T, double ell) override;
  kernels::TaylorSums taylor(const Eigen::Isometry3d& T, const Vector6d& xi, double ell) override;
  kernels::CurvatureSums curvature(const Eigen::Isometry3d& T, double ell) override;

 private:
  void countCall();

  std::unique_ptr<RegistrationBackend> inner_;
  long calls_left_;
};

}  // namespace cvo
