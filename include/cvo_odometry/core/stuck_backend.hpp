// A test backend: every sum is evaluated as if the source lay exactly on the target, so CVO
// returns its guess, converged, with a perfect cosine: the registration stuck near a wrong guess
// that the cosine cannot tell from a good one. The odometry must catch it by the feature tracks
// (test_fast_motion).
#pragma once

#include <memory>
#include <string>

#include "cvo_odometry/core/registration_backend.hpp"

namespace cvo {

class StuckBackend : public RegistrationBackend {
 public:
  explicit StuckBackend(std::unique_ptr<RegistrationBackend> inner);

  std::string name() const override { return inner_->name() + " (stuck, test)"; }
  void setProblem(const LabeledCloud& target, const LabeledCloud& source,
                  const CvoParams& params) override;
  void useSubsets(const CloudSubsets& subsets) override;
  kernels::MomentSums moments(const Eigen::Isometry3d& T, double ell) override;
  kernels::TaylorSums taylor(const Eigen::Isometry3d& T, const Vector6d& xi, double ell) override;
  kernels::CurvatureSums curvature(const Eigen::Isometry3d& T, double ell) override;

 private:
  std::unique_ptr<RegistrationBackend> inner_;
};

}  // namespace cvo
