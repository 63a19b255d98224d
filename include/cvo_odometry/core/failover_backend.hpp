// A primary backend (CUDA) that hands over to a secondary (CPU) when it throws: the failed call
// is replayed on the secondary, which serves until restore() (called at the start of each
// registration), so one bad frame falls back to the CPU with a warning instead of a wrong pose.
#pragma once

#include <memory>
#include <string>

#include "cvo_odometry/core/registration_backend.hpp"

namespace cvo {

class FailoverBackend : public RegistrationBackend {
 public:
  FailoverBackend(std::unique_ptr<RegistrationBackend> primary,
                  std::unique_ptr<RegistrationBackend> secondary);

  std::string name() const override;
  void setProblem(const LabeledCloud& target, const LabeledCloud& source,
                  const CvoParams& params) override;
  void useSubsets(const CloudSubsets& subsets) override;
  kernels::MomentSums moments(const Eigen::Isometry3d& T, double ell) override;
  kernels::MomentSums oneOffMoments(const Eigen::Isometry3d& T, double ell) override;
  kernels::TaylorSums taylor(const Eigen::Isometry3d& T, const Vector6d& xi, double ell) override;
  kernels::CurvatureSums curvature(const Eigen::Isometry3d& T, double ell) override;
  void setThreadLimit(int threads) override {
    primary_->setThreadLimit(threads);
    secondary_->setThreadLimit(threads);
  }
  std::optional<DeviceWork> deviceWork() const override { return primary_->deviceWork(); }

  void restore() { failed_ = false; }
  bool failedOver() const { return failed_; }
  // The primary's last error, empty if none.
  const std::string& lastError() const { return last_error_; }
  int failures() const { return failures_; }

 private:
  template <class Call>
  auto run(Call&& call);

  std::unique_ptr<RegistrationBackend> primary_, secondary_;
  bool failed_ = false;
  bool secondary_ready_ = false;
  int failures_ = 0;
  std::string last_error_;
  const LabeledCloud* target_ = nullptr;
  const LabeledCloud* source_ = nullptr;
  CvoParams params_;
  CloudSubsets subsets_;
};

}  // namespace cvo
