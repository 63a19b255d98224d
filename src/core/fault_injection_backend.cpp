#include "cvo_odometry/core/fault_injection_backend.hpp"

#include <stdexcept>

namespace cvo {

FaultInjectionBackend::FaultInjectionBackend(std::unique_ptr<RegistrationBackend> inner,
                                             long good_calls)
    : inner_(std::move(inner)), calls_left_(good_calls) {}

std::string FaultInjectionBackend::name() const {
  return inner_->name() + " (fault injection)";
}

void FaultInjectionBackend::countCall() {
  if (calls_left_ <= 0) {
    throw std::runtime_error("injected backend fault (test hook): an illegal memory access");
  }
  --calls_left_;
}

void FaultInjectionBackend::setProblem(const LabeledCloud& target, const LabeledCloud& source,
                                       const CvoParams& params) {
  inner_->setProblem(target, source, params);
}

void FaultInjectionBackend::useSubsets(const CloudSubsets& subsets) {
  inner_->useSubsets(subsets);
}

kernels::MomentSums FaultInjectionBackend::moments(const Eigen::Isometry3d& T, double ell) {
  countCall();
  return inner_->moments(T, ell);
}

kernels::MomentSums FaultInjectionBackend::oneOffMoments(const Eigen::Isometry3d& T, double ell) {
  countCall();
  return inner_->oneOffMoments(T, ell);
}

kernels::TaylorSums FaultInjectionBackend::taylor(const Eigen::Isometry3d& T, const Vector6d& xi,
                                                  double ell) {
  countCall();
  return inner_->taylor(T, xi, ell);
}

kernels::CurvatureSums FaultInjectionBackend::curvature(const Eigen::Isometry3d& T, double ell) {
  countCall();
  return inner_->curvature(T, ell);
}

}  // namespace cvo
