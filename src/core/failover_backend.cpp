#include "cvo_odometry/core/failover_backend.hpp"

#include <stdexcept>

namespace cvo {

FailoverBackend::FailoverBackend(std::unique_ptr<RegistrationBackend> primary,
                                 std::unique_ptr<RegistrationBackend> secondary)
    : primary_(std::move(primary)), secondary_(std::move(secondary)) {}

std::string FailoverBackend::name() const {
  return failed_ ? secondary_->name() + " (fallback: " + primary_->name() + " failed)"
                 : primary_->name();
}

template <class Call>
auto FailoverBackend::run(Call&& call) {
  if (!failed_) {
    try {
      return call(*primary_);
    } catch (const std::runtime_error& e) {
      failed_ = true;
      ++failures_;
      last_error_ = e.what();
      secondary_ready_ = false;
    }
  }
  if (!secondary_ready_) {
    if (!target_) throw std::logic_error("backend used before setProblem");
    secondary_->setProblem(*target_, *source_, params_);
    secondary_->useSubsets(subsets_);
    secondary_ready_ = true;
  }
  return call(*secondary_);
}

void FailoverBackend::setProblem(const LabeledCloud& target, const LabeledCloud& source,
                                 const CvoParams& params) {
  target_ = &target;
  source_ = &source;
  params_ = params;
  subsets_ = CloudSubsets{};
  secondary_ready_ = false;
  if (failed_) {
    secondary_->setProblem(target, source, params);
    secondary_ready_ = true;
    return;
  }
  run([&](RegistrationBackend& b) {
    b.setProblem(target, source, params);
    return 0;
  });
}

void FailoverBackend::useSubsets(const CloudSubsets& subsets) {
  subsets_ = subsets;
  if (failed_) {
    if (secondary_ready_) secondary_->useSubsets(subsets);
    return;
  }
  run([&](RegistrationBackend& b) {
    b.useSubsets(subsets);
    return 0;
  });
}

kernels::MomentSums FailoverBackend::moments(const Eigen::Isometry3d& T, double ell) {
  return run([&](RegistrationBackend& b) { return b.moments(T, ell); });
}

kernels::MomentSums FailoverBackend::oneOffMoments(const Eigen::Isometry3d& T, double ell) {
  return run([&](RegistrationBackend& b) { return b.oneOffMoments(T, ell); });
}

kernels::TaylorSums FailoverBackend::taylor(const Eigen::Isometry3d& T, const Vector6d& xi,
                                            double ell) {
  return run([&](RegistrationBackend& b) { return b.taylor(T, xi, ell); });
}

kernels::CurvatureSums FailoverBackend::curvature(const Eigen::Isometry3d& T, double ell) {
  return run([&](RegistrationBackend& b) { return b.curvature(T, ell); });
}

}  // namespace cvo
